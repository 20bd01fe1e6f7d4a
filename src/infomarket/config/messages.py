"""How a pydantic validation error reads for a user: one line per problem, keys written as in
experiment files (``swarm.groups[0].count``), the allowed keys named where an unknown one was found.

Kept apart from the schema's models so that both ``config.schema`` (re-validating a copy) and
``config.load`` (reading a file) turn errors into the same message without importing each other.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pydantic import ValidationError


def key_path(loc: tuple[Any, ...]) -> str:
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


def _allowed_keys(model: Any, loc: tuple[Any, ...]) -> list[str]:
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


def _union_errors(errors: list[Any], branches: Mapping[str, Any]) -> list[dict[str, Any]]:
    """One error per problem for union-typed keys: drop a branch's "not a dict" / "not a list" error
    when the other branch says what is really wrong, and take branch names out of locations."""
    out = []
    for err in errors:
        loc = err["loc"]
        branch = [p for p in loc if isinstance(p, str) and p in branches]
        if branch and err["type"] in ("model_type", "list_type") and any(
                e["loc"][:1] == loc[:1] and e["type"] not in ("model_type", "list_type") for e in errors):
            continue
        if branch and err["type"] in ("model_type", "list_type"):
            err = {**err, "msg": "expected one site {x, y, radius} or a list of them"}
        if branch:
            model = branches[branch[0]]
            err = {**err, "loc": tuple(p for p in loc if not (isinstance(p, str) and p in branches)),
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


def invalid(source: str, exc: ValidationError, model: Any, branches: Mapping[str, Any]) -> str:
    """The ConfigError message for ``exc`` raised validating ``model``; ``branches`` are the union
    branches pydantic names inside locations (left out of the key paths, their model's keys listed)."""
    lines = []
    for err in _union_errors(exc.errors(), branches):
        line = _describe(err)
        if err["type"] == "extra_forbidden":
            allowed = err.get("allowed") or _allowed_keys(model, err['loc'])
            line += f"; allowed keys here: {', '.join(allowed)}"
        lines.append(line)
    return f"{source}: invalid experiment\n  " + "\n  ".join(lines)
