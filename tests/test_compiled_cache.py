"""numba's disk cache for the package's own compiled functions (infomarket.compiled_cache): keyed by the
whole package's source, so an edited helper is never loaded stale through a function of another file that
inlines it, and saved one process at a time, the code before the index entry that names it."""
from __future__ import annotations

import ast
import fcntl
import os
import shutil
import sys
from pathlib import Path

import infomarket
from infomarket import compiled_cache
from infomarket import _numba_internals as ni
from infomarket._numba_internals import CPUDispatcher
from infomarket.compiled_cache import KEPT, PackageLocator, in_package
from infomarket.engine import step
from infomarket.ledger.poa import blocks
from infomarket.ledger import kernels


PACKAGE = Path(infomarket.__file__).parent

#: Two files of the package copied for the test: ``outer`` inlines ``inner``, which the test edits.
_OUTER = """from numba import njit

from ._probe_inner import inner


@njit(cache=True)
def outer(x):
    return 2 * inner(x)
"""
_INNER = """from numba import njit


@njit(forceinline=True, cache=True)
def inner(x):
    return x + {}
"""
#: A function numba cannot cache (it calls C through ctypes): numba warns, naming its file, and runs it.
_UNCACHEABLE = """import ctypes

from numba import njit

_labs = ctypes.CDLL(None).labs
_labs.restype = ctypes.c_long
_labs.argtypes = [ctypes.c_long]


@njit(cache=True)
def absolute(x):
    return _labs(x)
"""
_RUN = """import sys
sys.path.insert(0, {!r})
import infomarket
assert infomarket.__file__.startswith(sys.path[0])
from infomarket.engine._probe_outer import outer
from infomarket.engine._probe_uncacheable import absolute
print(outer(1), sum(outer.stats.cache_hits.values()), absolute(-3))
"""


def test_an_edited_helper_is_not_loaded_stale_through_a_function_of_another_file(procs, tmp_path):
    """``outer`` (one file) inlines ``inner`` (another).  numba's own locator stamps ``outer``'s cache with its
    file only, and after an edit of ``inner`` loaded the old ``outer`` from its cache (4, not 6)."""
    src = tmp_path / "src"
    shutil.copytree(PACKAGE, src / "infomarket", ignore=shutil.ignore_patterns("__pycache__"))
    (src / "infomarket" / "engine" / "_probe_outer.py").write_text(_OUTER)
    (src / "infomarket" / "engine" / "_probe_uncacheable.py").write_text(_UNCACHEABLE)
    inner = src / "infomarket" / "engine" / "_probe_inner.py"
    env = {"INFOMARKET_CACHE_DIR": str(tmp_path / "cache")}

    def run() -> list[str]:
        done = procs.run([sys.executable, "-c", _RUN.format(str(src))], env=env, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        assert 'Cannot cache compiled function "absolute"' in done.stderr and "_probe_uncacheable.py" in done.stderr
        return done.stdout.split()

    inner.write_text(_INNER.format(1))
    assert run() == ["4", "0", "3"]  # compiled, and cached
    assert run() == ["4", "1", "3"]  # loaded from the cache
    inner.write_text(_INNER.format(2))
    assert run() == ["6", "0", "3"]  # compiled again from the edited source
    assert run() == ["6", "1", "3"]
    assert len(list((tmp_path / "cache" / "compiled").iterdir())) == 2  # one folder per version of the source


def _held(lock: Path) -> bool:
    """Does another open file hold ``lock`` (flock excludes two opens even within one process)?"""
    with open(lock, "a") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(fh, fcntl.LOCK_UN)
        return False


def _index(folder: Path):
    """A function's cache files in ``folder``, as numba's ``Cache`` makes them once ``infomarket`` is imported."""
    folder.mkdir(parents=True, exist_ok=True)
    return ni.caching.IndexDataCacheFile(str(folder), "f-1-abc.py311", "stamp")


def test_a_save_writes_the_code_then_the_index_entry_under_the_lock(tmp_path, monkeypatch):
    monkeypatch.setattr(compiled_cache, "compiled_root", lambda: tmp_path)
    index = _index(tmp_path / "engine")
    seen = []
    save_data, save_index = index._save_data, index._save_index
    monkeypatch.setattr(index, "_save_data", lambda *a: (seen.append(("code", _held(tmp_path / "save.lock"))),
                                                          save_data(*a)))
    monkeypatch.setattr(index, "_save_index", lambda *a: (seen.append(("index", _held(tmp_path / "save.lock"))),
                                                           save_index(*a)))
    index.save("k1", "one")
    index.save("k2", "two")
    index.save("k1", "one again")
    assert seen == [("code", True), ("index", True)] * 3
    again = _index(tmp_path / "engine")  # another process's view
    assert (again.load("k1"), again.load("k2"), again.load("k3")) == ("one again", "two", None)
    assert len(list((tmp_path / "engine").glob("*.nbc"))) == 2


def test_a_cache_outside_the_package_is_saved_as_numba_saves_it(tmp_path, monkeypatch):
    monkeypatch.setattr(compiled_cache, "compiled_root", lambda: tmp_path / "ours")
    index = _index(tmp_path / "theirs")
    index.save("k", "code")
    assert index.load("k") == "code" and not (tmp_path / "ours").exists()


def _user_rule(x):
    return x


def test_the_package_functions_are_located_in_the_compiled_root_and_others_are_not():
    locator = PackageLocator.from_function(kernels.distribute.py_func, kernels.__file__)
    assert Path(locator.get_cache_path()) == compiled_cache.compiled_root() / "ledger"
    assert locator.get_source_stamp() == infomarket.generated.freeze_package_digest()
    assert PackageLocator.from_function(_user_rule, __file__) is None
    assert in_package(kernels.distribute.py_func) and not in_package(_user_rule)
    rule = infomarket.registry.get_behaviour("naive").buy
    assert in_package(rule.py_func)


def _uncached(source: str) -> list[str]:
    """Functions of ``source`` decorated ``@njit`` without saying ``cache=``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for d in node.decorator_list:
                call = d if isinstance(d, ast.Call) else None
                if ast.unparse(call.func if call else d).split(".")[-1] == "njit" and not (
                        call and any(k.arg == "cache" for k in call.keywords)):
                    found.append(node.name)
    return found


def test_the_uncached_finder():
    assert _uncached("@njit\ndef f(w):\n    pass\n\n@njit(cache=True)\ndef g(w):\n    pass\n\n"
                     "@numba.njit(forceinline=True)\ndef h(w):\n    pass\n\n@njit(cache=False)\ndef k(w):\n"
                     "    pass\n") == ["f", "h"]


def test_every_compiled_function_of_the_package_says_whether_it_is_cached():
    """A new helper left uncached would be compiled again in every process (docs/testing.md)."""
    offenders = {str(p.relative_to(PACKAGE)): names for p in PACKAGE.rglob("*.py")
                 if (names := _uncached(p.read_text()))}
    assert offenders == {}


def _closures() -> list:
    """The compiled closures the package makes (the step's variants, the chain's end of a step), and the
    compiled closures they capture."""
    todo = [*(f for t in (False, True) for p in (False, True) for f in step._variant(t, p)),
            blocks.end_of_step(kernels.distribute)]
    found = []
    while todo:
        f = todo.pop()
        if isinstance(f, CPUDispatcher) and f.py_func.__closure__ and f not in found:
            found.append(f)
            todo += [c.cell_contents for c in f.py_func.__closure__]
    return found


def test_no_cached_closure_captures_a_compiled_function():
    """Its cache key (its captured values, pickled) would differ in every process: never found, always added."""
    closures = _closures()
    assert {f.py_func.__name__ for f in closures} >= {"sense_sites", "behaviour_step", "apply_block", "make_blocks"}
    offenders = {f.py_func.__qualname__ for f in closures
                 if f.stats.cache_path is not None
                 and any(isinstance(c.cell_contents, CPUDispatcher) for c in f.py_func.__closure__)}
    assert offenders == set()


def test_a_new_version_keeps_the_latest_used_folders_and_deletes_the_rest(tmp_path):
    """Every edit of the package starts a folder of about 130 MB: the ``KEPT`` most recently used stay."""
    parent = tmp_path / "compiled"
    for k in range(6):
        (parent / f"v{k}").mkdir(parents=True)
        (parent / f"v{k}" / "used").touch()
        os.utime(parent / f"v{k}" / "used", (1000 + k, 1000 + k))  # v5 used last
    (parent / "v0" / "used").unlink()  # never marked: the oldest
    root = compiled_cache.opened(parent / "new")
    assert root == parent / "new" and (root / "used").exists()
    assert sorted(p.name for p in parent.iterdir()) == sorted(["new", *(f"v{k}" for k in range(6 - KEPT + 1, 6))])
    compiled_cache.opened(parent / "v3")  # a kept version's process comes back: marked used, nothing deleted
    assert sorted(p.name for p in parent.iterdir()) == ["new", "v3", "v4", "v5"]
    compiled_cache.opened(parent / "v1")  # a deleted one's: made again, and the least recently used goes
    assert sorted(p.name for p in parent.iterdir()) == ["new", "v1", "v3", "v5"]
