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
from typing import Any

from pydantic import ValidationError

from ..errors import ConfigError
from .legacy import from_legacy, is_legacy
from .schema import NAME_MAX, CircleObstacle, Experiment, Rect, Segment

SHIPPED = "infomarket.experiments"


def shipped_experiments() -> dict[str, Path]:
    """Experiment files that ship with the package, by name (e.g. ``fig2A``)."""
    found: dict[str, Path] = {}
    root = resources.files(SHIPPED)
    for sub in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith("_")):
        for f in sorted(sub.iterdir()):
            if f.name.endswith(".toml"):
                found[f.name[:-5]] = Path(str(f))
    return found


def key_path(loc: tuple) -> str:
    """A validation location as users write keys: ``swarm.groups[0].count`` (as in sweep grids)."""
    out = ""
    for part in loc:
        if part in ("function-after[_coherent()]",):
            continue
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _shown(value: Any, limit: int = 80) -> str:
    """A value as an error message quotes it: its repr (control characters escaped), cut to ``limit``."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def _describe(err: dict[str, Any]) -> str:
    loc = key_path(err["loc"])
    msg = err["msg"]
    if err["type"] == "extra_forbidden":
        return f"{loc}: unknown key"
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    got = err.get("input")
    shown = "" if isinstance(got, dict) or err["type"] == "missing" else f" (got {_shown(got)})"
    return f"{loc + ': ' if loc else ''}{msg}{shown}"


def _allowed_keys(model: type, loc: tuple) -> list[str]:
    """Field names allowed where an unknown key was found."""
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        field = model.model_fields.get(part)
        if field is None:
            return []
        ann = field.annotation
        inner = getattr(ann, "__args__", None)
        if inner and hasattr(inner[0], "model_fields"):
            ann = inner[0]
        if not hasattr(ann, "model_fields"):
            return []
        model = ann
    return sorted(model.model_fields)


#: Union branches that pydantic names inside error locations (``food`` is one site or a list of sites;
#: an obstacle's ``shape`` picks its model): left out of the key paths users see.
_BRANCHES = {"Site": None, "list[Site]": None, "rect": Rect, "circle": CircleObstacle, "segment": Segment}


def _union_errors(errors: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One error per problem for union-typed keys: drop a branch's "not a dict" / "not a list" error
    when the other branch says what is really wrong, and take branch names out of locations."""
    out = []
    for err in errors:
        loc = err["loc"]
        branch = [p for p in loc if isinstance(p, str) and p in _BRANCHES]
        if branch and err["type"] in ("model_type", "list_type") and any(
                e["loc"][:1] == loc[:1] and e["type"] not in ("model_type", "list_type") for e in errors):
            continue
        if branch and err["type"] in ("model_type", "list_type"):
            err = {**err, "msg": "expected one site {x, y, radius} or a list of them"}
        if branch:
            model = _BRANCHES[branch[0]]
            err = {**err, "loc": tuple(p for p in loc if not (isinstance(p, str) and p in _BRANCHES)),
                   "allowed": sorted(model.model_fields) if model else None}
        if err["type"] == "union_tag_invalid" or err["type"] == "union_tag_not_found":
            err = {**err, "msg": "shape must be one of rect, circle, segment"}
        out.append(err)
    kept, seen = [], set()
    for err in out:  # a deeper error explains a branch mismatch above it; say each thing once
        deeper = err["type"] in ("model_type", "list_type") and any(
            len(e["loc"]) > len(err["loc"]) and e["loc"][:len(err["loc"])] == err["loc"] for e in out)
        key = (err["loc"], err["msg"])
        if not deeper and key not in seen:
            seen.add(key)
            kept.append(err)
    return kept


def validate(data: dict[str, Any], source: str = "configuration", base: Path | None = None) -> Experiment:
    """Validate a dictionary in our schema; raise ConfigError listing every problem.  ``base`` is the
    folder relative plugin paths are resolved against (the experiment file's)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: an experiment is a table of keys (a dict), got {type(data).__name__}")
    try:
        return Experiment.model_validate(data, context={"base": base})
    except RecursionError:
        raise ConfigError(f"{source}: nested too deeply to be an experiment") from None
    except ValidationError as exc:
        lines = []
        for err in _union_errors(exc.errors()):
            line = _describe(err)
            if err["type"] == "extra_forbidden":
                allowed = err.get("allowed") or _allowed_keys(Experiment, err['loc'])
                line += f"; allowed keys here: {', '.join(allowed)}"
            lines.append(line)
        raise ConfigError(f"{source}: invalid experiment\n  " + "\n  ".join(lines)) from None


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
    try:
        text = path.read_text(encoding="utf-8-sig")  # a byte-order mark (some editors write one) is not TOML
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
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
