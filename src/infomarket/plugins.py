"""Plugins: modules that register behaviours or payment schemes, named by an experiment file.

An entry is a module name (``mylab.rules``, importable from the current folder too) or the path of a
``.py`` file, relative to the experiment file.  Worker processes import the same entries before running.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
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


def load(entry: str) -> None:
    """Import a plugin (idempotent); raises ImportError with a readable message."""
    if entry.endswith(".py"):
        path = Path(entry)
        if not path.exists():
            raise PluginError(f"no such file {entry}")
        name = "infomarket_plugin_" + hashlib.sha1(str(path).encode()).hexdigest()[:12] + "_" + path.stem
        if name in sys.modules:
            return
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except Exception:
            del sys.modules[name]
            raise
        return
    try:
        importlib.import_module(entry)
    except ModuleNotFoundError:
        cwd = os.getcwd()
        if cwd in sys.path:
            raise
        sys.path.insert(0, cwd)  # like ``python -m``: the current folder's modules are importable
        importlib.import_module(entry)
