"""Generated modules on disk (step kernels, state views), so numba's cache can keep what it compiles.

numba's on-disk cache keys a function by its source file, so code specialised at run time (a closure over
the configured rules) would be recompiled in every process.  Generated source is written once to a file
whose name hashes everything its machine code depends on, and imported from there.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType

import numba

from ._version import __version__

_PACKAGE = Path(__file__).resolve().parent
_LOADED: dict[str, ModuleType] = {}
_PACKAGE_DIGEST: list[str] = []

#: Subpackages whose code ends up inside compiled kernels.
COMPILED_PARTS = ("engine", "behaviours", "payments", "ledger", "state", "space")


def _digest_now() -> str:
    """Hash of the compiled parts' source as it is on disk now."""
    h = hashlib.sha256()
    files = [f for part in COMPILED_PARTS for f in (_PACKAGE / part).rglob("*.py")]
    files.append(_PACKAGE / "builtins.py")
    for f in sorted(files):
        h.update(str(f.relative_to(_PACKAGE)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def freeze_package_digest() -> str:
    """Hash of the source that compiled code comes from, taken once, while ``import infomarket`` imports it
    (at its first compiled function, ``compiled_cache``): the code this process runs.  The generated kernel
    inlines engine code from many modules, and numba only checks the generated file itself for staleness,
    so any change there must change the kernel's name."""
    if not _PACKAGE_DIGEST:
        _PACKAGE_DIGEST.append(_digest_now())
    return _PACKAGE_DIGEST[0]


def source_changed_since_import() -> bool:
    """The compiled parts' source on disk is no longer what this process imported (edited while it ran):
    what it compiles now comes from the old code, so it must not be cached under the new code's name.  A
    helper's test run once cached old code that way and later runs of the new code loaded it."""
    return _digest_now() != freeze_package_digest()


def cache_root() -> Path:
    """The folder of everything infomarket caches (``INFOMARKET_CACHE_DIR``, else ~/.cache/infomarket)."""
    root = os.environ.get("INFOMARKET_CACHE_DIR")
    return Path(root) if root else Path.home() / ".cache" / "infomarket"


def cache_dir() -> Path:
    """Where generated kernels live (``cache_root()/kernels``)."""
    return cache_root() / "kernels"


def load_generated(prefix: str, key: str, source: str, cacheable: bool = True) -> ModuleType:
    """Import generated ``source`` as the module ``infomarket_PREFIX_KEY`` from ``cache_dir()/PREFIX_KEY.py``
    (written once, atomically), so numba caches what it compiles there; ``key`` must hash everything
    the source and its machine code depend on.  Not ``cacheable``: a fresh temporary folder."""
    name = f"{prefix}_{key}"
    if name in _LOADED:
        return _LOADED[name]
    if cacheable and source_changed_since_import():
        import warnings

        warnings.warn("infomarket's source changed on disk since this process imported it: kernels compiled "
                      "now come from the old code and are not cached (restart the process to cache again)",
                      RuntimeWarning, stacklevel=2)
        cacheable = False
    folder = cache_dir() if cacheable else Path(tempfile.mkdtemp(prefix="infomarket-kernel-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.exists():  # never rewrite: numba's cache index is stamped with the file's mtime
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        with os.fdopen(fd, "w") as fh:
            fh.write(source)
        os.replace(tmp, path)
    spec = importlib.util.spec_from_file_location(f"infomarket_{name}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[f"infomarket_{name}"] = module
    spec.loader.exec_module(module)
    _LOADED[name] = module
    return module


def generated_digest(source: str):
    """sha256 of ``source`` with the versions and the compiled package's own source mixed in."""
    digest = hashlib.sha256(source.encode())
    digest.update(f"{__version__} {numba.__version__} {sys.version} {freeze_package_digest()}".encode())
    return digest


def compile_marker(module: ModuleType, tag: str) -> Path | None:
    """The file that notes that ``module``'s functions were compiled (for ``tag``, a use of them) and are
    in numba's disk cache (``interrupts.compiled_apart``); None when the module is not in the cache folder
    (compiled in a temporary one: a child's compile would not be found)."""
    path = Path(module.__file__)
    if path.parent != cache_dir():
        return None
    return path.with_name(f"{path.stem}.{tag}.compiled")
