"""numba's disk cache for infomarket's own compiled functions, keyed by the package's source.

A step kernel inlines a few hundred helpers (the step's pieces, the ledgers, the built-in rules).  numba
types and compiles each once per process: most of what a fresh process spent on its first kernel, whatever
its kernel cache held (docs/testing.md, "A fifth round").  With ``cache=True`` a helper is loaded instead:
its signature and machine code, and its LLVM bitcode, which a new kernel still inlines.  numba's own locator
stamps a function's cache with its file's time and size only, but a helper inlines helpers of other files;
an edit there would leave it stale.  So a function of this package is cached in a folder named by the
digest of every compiled part (``generated.freeze_package_digest``), numba's and Python's versions, and its
file's own hash: any edit gives a fresh cache and never a stale one.

Saving is one process at a time (``save_lock``; the ordered save is in ``_numba_internals``): numba reads a
function's index, adds its entry and writes it back, then writes the code. Two processes compiling one
helper for two view types at once (two test workers, a sweep's) could then leave an index that names a
file holding the other signature's code.

Every ``@njit`` of the package says ``cache=``.  A closure that captures compiled functions says
``cache=False``: numba keys a closure's cache by its captured values, pickled, and a compiled function
pickles differently in every process, so each process would add an entry and none would find one.
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import shutil
import sys
from pathlib import Path

import numba

from . import _numba_internals as ni
from .generated import cache_root, freeze_package_digest

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: numba's saves as they are
    fcntl = None

_PACKAGE = Path(__file__).resolve().parent


#: How many versions of the package's compiled functions are kept, the most recently used: every edit of the
#: package starts a new one, which holds every piece compiled for that version.
KEPT = 4


@functools.cache
def compiled_root() -> Path:
    """The folder of this code's cached functions: one per digest of the package and versions.  Fixed at the
    first function decorated (the code of a process does not change); marked used, and on its creation all
    but the ``KEPT`` most recently used folders beside it are deleted (an older version's is never read
    again; a process still running one would compile again what it misses)."""
    key = hashlib.sha256(f"{freeze_package_digest()} {numba.__version__} {sys.version}".encode()).hexdigest()
    return opened(cache_root() / "compiled" / key[:20])


def opened(root: Path) -> Path:
    """``root``, marked used now; when it is new, the folders beside it pruned to the ``KEPT`` latest used."""
    new = not root.exists()
    with contextlib.suppress(OSError):  # a read-only cache: numba then finds it cannot write there
        root.mkdir(parents=True, exist_ok=True)
        (root / "used").touch()
        if new:
            folders = [p for p in root.parent.iterdir() if p.is_dir()]
            for old in sorted(folders, key=_last_used, reverse=True)[KEPT:]:
                shutil.rmtree(old, ignore_errors=True)
    return root


def _last_used(folder: Path) -> float:
    try:
        return (folder / "used").stat().st_mtime
    except OSError:
        return 0.0


@functools.cache
def _file_hash(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def in_package(func) -> bool:
    """Is ``func`` written in this package (a built-in rule), so cached here?  A user's rule is not cached:
    numba's own cache would not see an edit of the helpers it calls."""
    code = getattr(func, "__code__", None)
    return code is not None and _PACKAGE in Path(code.co_filename).resolve().parents


class PackageLocator(ni.CacheLocator):
    """Where numba caches a function of this package (``compiled_root``), under its file's path in the package;
    other functions (a user's rules, generated kernels) are left to numba's own locators."""

    def __init__(self, py_file: Path, line: int):
        self._py_file = str(py_file)  # numba's warning that a function cannot be cached names it
        self._relative = py_file.relative_to(_PACKAGE)
        self._root = compiled_root()
        self._name = f"{line}-{_file_hash(py_file)}"

    @classmethod
    def from_function(cls, py_func, py_file):
        """A locator for a function defined in the package's own files; None for any other (numba then tries its
        other locators)."""
        path = Path(py_file).resolve()
        if _PACKAGE not in path.parents or not path.is_file():
            return None
        return cls(path, py_func.__code__.co_firstlineno)

    def get_cache_path(self) -> str:
        """The cache folder for the function's file, under the folder named by the package's digest."""
        return str(self._root / self._relative.parent)

    def get_source_stamp(self) -> str:
        """The package digest, the same for every file: the folder is named by it already, so an index found there
        is never stale."""
        return freeze_package_digest()  # the folder is named by it already: a fresh index is never stale

    def get_disambiguator(self) -> str:
        """What tells apart functions of the same name in one file: their line (and the file's own hash outside the
        compiled parts)."""
        return self._name  # its line, and its file's own hash (for files outside the digest's compiled parts)


@contextlib.contextmanager
def _saving(root: Path):
    """Hold the lock of ``root`` while a save reads and writes an index there (a few milliseconds)."""
    root.mkdir(parents=True, exist_ok=True)
    with open(root / "save.lock", "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def save_lock(cache_path):
    """The lock a save into ``cache_path`` takes: this package's cache's (one for all its functions), or None
    (a cache elsewhere, or no ``fcntl``: numba's save as it is)."""
    root, path = compiled_root(), Path(cache_path)
    if fcntl is None or not (path == root or root in path.parents):
        return None
    return _saving(root)


def install() -> None:
    """Use ``PackageLocator`` and ``save_lock`` for every function decorated from now on (``cache=True``);
    called by ``import infomarket`` before any of its compiled modules is imported."""
    ni.install_cache(PackageLocator, save_lock)
