"""Read experiment files (our TOML, or the original JSON format) and turn every problem into one
``ConfigError`` whose message names the file, the key and what is allowed."""
from __future__ import annotations

import difflib
import json
import os
import re
import tomllib
from importlib import resources
from pathlib import Path

from ..errors import ConfigError
from ..userfiles import read_text
from .legacy import from_legacy, is_legacy
from .messages import key_path  # noqa: F401  (where callers have found it)
from .schema import NAME_MAX, Experiment, validate

SHIPPED = "infomarket.experiments"


def shipped_experiments() -> dict[str, Path]:
    """Experiment files that ship with the package, by name (e.g. ``fig2A``)."""
    found: dict[str, Path] = {}
    root = resources.files(SHIPPED)
    for sub in sorted((p for p in root.iterdir() if p.is_dir() and not p.name.startswith("_")), key=lambda p: p.name):
        for f in sorted(sub.iterdir(), key=lambda f: f.name):
            if f.name.endswith(".toml"):
                found[f.name[:-5]] = Path(str(f))
    return found


def looks_like_path(what: str) -> bool:
    """Does a command-line argument name a file or folder rather than a shipped experiment?  Yes when it has
    a folder part or a trailing separator (``./fig2A``, ``runs/fig2A``, ``fig2A/``) or an extension
    (``fig2A.toml``)."""
    text = str(what)
    return "/" in text or os.sep in text or (os.altsep is not None and os.altsep in text) or Path(text).suffix != ""


def default_name(stem: str) -> str:
    """An experiment name made from a file's stem when the file sets none: the characters a name may not
    hold become ``_`` (schema.NAME_PATTERN), and it is cut to the longest name allowed."""
    name = re.sub(r"[^A-Za-z0-9_.+=,-]", "_", stem)[:NAME_MAX].lstrip(".-+=,")
    return name or "experiment"


def load_experiment(what: str | Path) -> Experiment:
    """Load an experiment from a ``.toml`` or ``.json`` file, or by the name of a shipped one.

    A shipped name (``fig2A``) wins over a file or folder of the same name in the working directory, so
    that ``infomarket sweep fig2A --out fig2A`` can be run again; write ``./fig2A`` (or give a path with a
    folder or an extension) to name the file instead."""
    shipped = shipped_experiments()
    if isinstance(what, str) and not what.strip():  # Path("") is the current folder: name what is missing
        raise ConfigError(f"experiment {what!r}: empty; name a shipped experiment (e.g. fig2A) or a .toml / .json "
                          f"file")
    if isinstance(what, str) and what in shipped and not looks_like_path(what):
        path = shipped[what]
    else:
        path = Path(what)
        try:
            exists = path.exists()
        except (OSError, ValueError) as exc:  # a name too long for the file system, a NUL byte
            raise ConfigError(f"{str(what)[:200]!r}: not an experiment file or a shipped name ({exc})") from None
        if not exists:
            raise ConfigError(f"no experiment file {str(what)[:200]!r} and no shipped experiment of that name"
                              f"{_did_you_mean(str(what), shipped)}; shipped: {', '.join(shipped)}")
    if path.is_dir():
        other = (f"; the shipped experiment {path.name} is named without a folder or a trailing /: `{path.name}`"
                 if path.name in shipped else "")
        raise ConfigError(f"{path}: is a directory, not an experiment file (.toml or .json){other}")
    # a regular file of a sane size only (a device or a FIFO named by mistake is never read whole); a
    # byte-order mark (some editors write one) is dropped: it is not TOML
    text = read_text(path, ConfigError, "experiment file")
    try:
        return _parse(path, text)
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be an experiment file") from None


def _did_you_mean(what: str, shipped: dict[str, Path]) -> str:
    """``; did you mean fig2B?`` for a shipped name given in another case or with a typo."""
    same = [n for n in shipped if n.lower() == what.lower()]
    close = same or difflib.get_close_matches(what, list(shipped), n=1, cutoff=0.75)
    return f"; did you mean {close[0]}?" if close else ""


#: Deepest nesting of arrays and tables an experiment file may have (real ones need 4 or 5): deeper ones are
#: refused before parsing, since the parsers recurse and a deep enough file overflows the stack.
MAX_NESTING = 64


def nesting_depth(text: str, comments: bool) -> int:
    """The deepest nesting of ``[``/``{`` in ``text``, outside strings ("..." with escapes, '...' without)
    and, with ``comments``, outside ``#`` comments (TOML)."""
    depth = deepest = 0
    quote = ""
    escaped = comment = False
    for c in text:
        if comment:
            comment = c != "\n"
        elif quote:
            if escaped:
                escaped = False
            elif c == "\\" and quote == '"':
                escaped = True
            elif c == quote:
                quote = ""
        elif c in "[{":
            depth += 1
            if depth > deepest:
                deepest = depth
                if deepest > MAX_NESTING:
                    return deepest
        elif c in "]}":
            depth = max(0, depth - 1)
        elif c == '"' or (c == "'" and comments):
            quote = c
        elif c == "#" and comments:
            comment = True
    return deepest


def _parse(path: Path, text: str) -> Experiment:
    if path.suffix in (".toml", ".json") and nesting_depth(text, path.suffix == ".toml") > MAX_NESTING:
        raise ConfigError(f"{path}: nested more than {MAX_NESTING} levels deep; not an experiment file")
    if path.suffix == ".toml":
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    elif path.suffix == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{path}: not valid JSON: {exc}") from None
        if not isinstance(data, dict):
            raise ConfigError(f"{path}: the top level must be a JSON object")
        if is_legacy(data):
            try:
                data = from_legacy(data, default_name(path.stem))
            except ConfigError as exc:
                raise ConfigError(f"{path}: {exc}") from None
    else:
        raise ConfigError(f"{path}: unknown file type {path.suffix!r}; use .toml (or the original .json)")
    data.setdefault("name", default_name(path.stem))
    return validate(data, str(path), base=path.resolve().parent)
