"""What a results store records about the questions and decision rules it was created under.

When a store is created (before its first run) it records a fingerprint of every file that declares
questions or decision rules: the SHA-256 of the file and of each of its declarations (each
``[rows.ID]``, ``[questions.ID]`` and ``[statistics]`` table, hashed as canonical JSON, so comments and
reordering do not count as edits).  ``analysis.declared`` compares that record with the files a report
answers from.  The files are the analysis package's data; this module reads them as files, so the store
never imports the analysis code that reads stores.
"""
from __future__ import annotations

import hashlib
import json
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parents[1] / "analysis"
#: the files that declare questions or decision rules, by the name the store records them under
FILES = {"tolerances.toml": HERE / "tolerances.toml", "terrain_questions.toml": HERE / "terrain_questions.toml",
         "sensitivity_questions.toml": HERE / "sensitivity_questions.toml",
         "chain_questions.toml": HERE / "chain_questions.toml"}
SECTIONS = ("rows", "questions")


def _hash(data) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True, ensure_ascii=True).encode()).hexdigest()


def fingerprint_file(path: Path) -> dict:
    """``{"sha256": file hash, "sections": {"questions.ID": hash, ...}}`` of one declaration file."""
    raw = Path(path).read_bytes()
    data = tomllib.loads(raw.decode())
    sections = {}
    for top, value in data.items():
        if top in SECTIONS and isinstance(value, dict):
            sections.update({f"{top}.{k}": _hash(v) for k, v in value.items()})
        else:
            sections[top] = _hash(value)
    return {"sha256": hashlib.sha256(raw).hexdigest(), "sections": sections}


def fingerprint(files: dict[str, Path] | None = None) -> dict:
    """The fingerprint of every declaration file, as the store records it."""
    return {name: fingerprint_file(p) for name, p in (FILES if files is None else files).items()}
