"""infomarket.jit: the package's compiled functions, and the rules registered through ``registry``, are
compiled without numba's C-callable wrapper (nothing passes them as first-class functions), and every
compiled function of the package goes through that one decorator."""
import re
from pathlib import Path

import numba

import infomarket
from infomarket.engine.geometry import wrap360
from infomarket.jit import njit
from infomarket.registry import rule_function

SRC = Path(infomarket.__file__).parent


def _has_c_wrapper(dispatcher) -> bool:
    return any(re.search(r"define [^\n]*@\"?cfunc\.", ir) for ir in dispatcher.inspect_llvm().values())


def test_numbas_own_njit_compiles_the_wrapper_this_test_looks_for():
    @numba.njit
    def plain(x):
        return x + 1.0

    plain(1.0)
    assert _has_c_wrapper(plain)


def test_a_piece_of_the_package_and_a_registered_rule_have_no_c_wrapper():
    @njit
    def ours(x):
        return x + 1.0

    ours(1.0)
    wrap360(370.0)
    assert not _has_c_wrapper(ours) and not _has_c_wrapper(wrap360)

    rule = rule_function("behaviour", "naive", "buy")  # a built-in rule, registered as users register theirs
    assert rule.targetoptions.get("no_cfunc_wrapper") is True


def test_every_compiled_function_of_the_package_goes_through_its_njit():
    numba_jit = re.compile(r"from numba import[^\n]*\b(n?jit)\b|numba\.n?jit\(")
    offenders = [str(p.relative_to(SRC)) for p in SRC.rglob("*.py")
                 if p.name != "jit.py" and numba_jit.search(p.read_text())]
    assert offenders == []
