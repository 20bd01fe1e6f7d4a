"""Build the step kernel specialised to a set of rules, as real source on disk so numba caches it.

numba's on-disk cache keys a function by its source file, so closures over the configured rules, or
rules passed as arguments, are recompiled in every process.  Instead we write a small module: the
step-loop template (``engine/_loop.py``) followed by dispatch functions that call each configured rule
directly.  Its file name hashes everything that could change the machine code (template, every rule's
source, versions), so an edited rule gets a new kernel and an unchanged one is loaded from the cache.
"""
from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType

import numba

from .. import __version__
from ..registry import BehaviourSpec, PaymentSpec, Rule, get_behaviour, get_payment
from .worldref import constructor_source

_TEMPLATE = Path(__file__).with_name("_loop.py")
_PACKAGE = Path(__file__).resolve().parents[1]
_LOADED: dict[str, ModuleType] = {}
_PACKAGE_DIGEST: list[str] = []


#: Subpackages whose code ends up inside compiled kernels.
_COMPILED_PARTS = ("engine", "behaviours", "payments", "ledger")


def _package_digest() -> str:
    """Hash of the source that compiled code comes from: the generated kernel inlines engine code from
    many modules, and numba only checks the generated file itself for staleness, so any change there
    must change the kernel's name."""
    if not _PACKAGE_DIGEST:
        h = hashlib.sha256()
        files = [f for part in _COMPILED_PARTS for f in (_PACKAGE / part).rglob("*.py")]
        for f in sorted(files):
            h.update(str(f.relative_to(_PACKAGE)).encode())
            h.update(f.read_bytes())
        _PACKAGE_DIGEST.append(h.hexdigest())
    return _PACKAGE_DIGEST[0]


def cache_dir() -> Path:
    """Where generated kernels live (``INFOMARKET_CACHE_DIR``, else ~/.cache/infomarket/kernels)."""
    root = os.environ.get("INFOMARKET_CACHE_DIR")
    base = Path(root) if root else Path.home() / ".cache" / "infomarket"
    return base / "kernels"


def _rule_source(rule: Rule) -> str | None:
    py = rule.py_func
    try:
        text = inspect.getsource(py)
        module = inspect.getmodule(py)
        whole = inspect.getsource(module) if module is not None else ""
    except (OSError, TypeError):
        return None
    return f"{py.__module__}.{py.__qualname__}\n{text}\n{whole}"


def _args(rule: Rule, spec_params: tuple[str, ...], row: str) -> str:
    rng = ", rng" if rule.wants_rng else ""
    return rng + "".join(f", {row}[{spec_params.index(p)}]" for p in rule.params)


def generate_source(behaviours: list[BehaviourSpec], payment: PaymentSpec) -> str:
    """Source of the specialised module (template + dispatch) for these behaviours, in kind order."""
    lines = [_TEMPLATE.read_text(), "", "# ---- generated dispatch " + "-" * 60,
             "from infomarket.registry import rule_function as _rule_function", ""]
    for k, b in enumerate(behaviours):
        lines.append(f"_b{k}_buy = _rule_function('behaviour', {b.name!r}, 'buy')")
        lines.append(f"_b{k}_sell = _rule_function('behaviour', {b.name!r}, 'sell')")
    lines.append(f"_pay = _rule_function('payment', {payment.name!r}, 'weights')")
    lines += ["", "", "@njit(cache=True)", "def sell_dispatch(kind, w, i, site, rng):"]
    for k, b in enumerate(behaviours):
        call = f"return _b{k}_sell(w, i, site{_args(b.sell, b.params, 'w.bparams[i]')})"
        if k == len(behaviours) - 1:
            lines.append(f"    {call}")
        else:
            lines += [f"    if kind == {k}:", f"        {call}"]
    lines += ["", "", "@njit(cache=True)", "def buy_dispatch(kind, w, i, nbrs, rng):"]
    for k, b in enumerate(behaviours):
        lines += [f"    {'if' if k == 0 else 'elif'} kind == {k}:",
                  f"        _b{k}_buy(w, i, nbrs{_args(b.buy, b.params, 'w.bparams[i]')})"]
    lines += ["", "", "@njit(cache=True)", "def pay_dispatch(w, buyer, sellers, sites, directions, weights, rng):",
              f"    _pay(buyer, sellers, sites, directions, weights{_args(payment.weights, payment.params, 'w.pparams')})",
              "", "", "from numba.experimental.structref import new as _structref_new",
              "from infomarket.engine.worldref import world_type as _world_type",
              "_WORLD_TYPE = _world_type()", "", "", constructor_source()]
    return "\n".join(lines)


def kernel_module(behaviour_names: tuple[str, ...], payment_name: str) -> ModuleType:
    """The specialised kernel module (``run_steps``) for these behaviours (kind order) and scheme."""
    behaviours = [get_behaviour(b) for b in behaviour_names]
    payment = get_payment(payment_name)
    source = generate_source(behaviours, payment)
    digest = hashlib.sha256(source.encode())
    digest.update(f"{__version__} {numba.__version__} {sys.version} {_package_digest()}".encode())
    cacheable = True
    for rule in [r for b in behaviours for r in (b.buy, b.sell)] + [payment.weights]:
        text = _rule_source(rule)
        if text is None:  # e.g. typed at an interactive prompt: compile, but never reuse from disk
            cacheable = False
            text = repr(id(rule.func))
        digest.update(text.encode())
    key = digest.hexdigest()[:20]
    if key in _LOADED:
        return _LOADED[key]
    folder = cache_dir() if cacheable else Path(tempfile.mkdtemp(prefix="infomarket-kernel-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"kernel_{key}.py"
    if not path.exists():  # never rewrite: numba's cache index is stamped with the file's mtime
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "w") as fh:
            fh.write(source)
        os.replace(tmp, path)
    name = f"infomarket_kernel_{key}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    _LOADED[key] = module
    return module
