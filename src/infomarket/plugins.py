"""Plugins: modules that register behaviours or payment schemes, named by an experiment file.

An entry is a module name (``mylab.rules``, importable from the current folder too) or the path of a
``.py`` file, relative to the experiment file.  Worker processes import the same entries before running.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import re
import sys
from pathlib import Path

from .errors import PluginError


def resolve(entry: str, base: Path | None) -> str:
    """The canonical form of an entry: an absolute path for files, the module name otherwise."""
    if entry.endswith(".py"):
        path = Path(entry)
        if not path.is_absolute():
            path = (base or Path.cwd()) / path
        return str(path.resolve())
    return entry


#: A module entry: dotted Python identifiers (``mylab.rules``).
_MODULE = re.compile(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*")


def load(entry: str) -> None:
    """Import a plugin (idempotent); raises ImportError with a readable message.  A plugin that calls
    ``sys.exit`` while being imported is a PluginError too (it would end the command silently)."""
    try:
        _load(entry)
    except SystemExit as exc:
        raise PluginError(f"{entry}: the plugin called sys.exit({exc.code!r}) while being imported; a plugin "
                          f"module should only define and register rules") from None


def _load(entry: str) -> None:
    if entry.endswith(".py"):
        path = Path(entry)
        if not path.exists():
            raise PluginError(f"no such file {entry}")
        if not path.is_file():
            raise PluginError(f"{entry} is not a file")
        name = "infomarket_plugin_" + hashlib.sha1(str(path).encode()).hexdigest()[:12] + "_" + path.stem
        if name in sys.modules:
            return
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise PluginError(f"{entry} cannot be loaded as a Python module")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except Exception:
            del sys.modules[name]
            raise
        return
    if Path(entry).is_file():
        raise PluginError(f"{entry} is a file but not a .py file: a plugin is a .py file or a module name")
    if not _MODULE.fullmatch(entry):
        raise PluginError(f"{entry!r} is neither a .py file nor a module name (like mylab.rules)")
    try:
        importlib.import_module(entry)
    except ModuleNotFoundError:
        cwd = os.getcwd()
        if cwd in sys.path:
            raise
        sys.path.insert(0, cwd)  # like ``python -m``: the current folder's modules are importable
        importlib.import_module(entry)
