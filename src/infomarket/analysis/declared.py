"""Questions locked to the store: which decision rules existed, unchanged, before a store's first run.

A results store records, when it is created (``Store.create``, at the start of every sweep, before its
first run), a fingerprint of every file that declares questions or decision rules: the SHA-256 of the
file and of each of its declarations (each ``[rows.ID]``, ``[questions.ID]`` and ``[statistics]`` table,
hashed as canonical JSON, so comments and reordering do not count as edits but any changed parameter
or rule text does).  A report compares that record with the files it answers from:

- ``declared``: the declaration is in the record with the same hash: it was declared before the store's
  first run and has not been edited since;
- ``edited``: in the record with another hash: the rule was edited after the store's first run;
- ``added``: not in the record: declared after the store's first run;
- ``not recorded``: the store predates the record (made before stores kept one): nothing can be said.

A file's record of amendments and deviations (``[[amendments]]``, ``[[deviations]]``, read by
``analysis.study``) is a note about its declarations, not one: it is left out.

A question that declares ``runs`` (its planned run count) is also checked against the runs it is
answered with (``size_note``).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..store.declarations import FILES, SECTIONS, fingerprint, fingerprint_file  # noqa: F401  (the record's format)

DECLARED, EDITED, ADDED, NOT_RECORDED = "declared", "edited", "added", "not recorded"
NOTES = ("amendments", "deviations")  # a file's record of its history, not declarations


@dataclass(frozen=True)
class Lock:
    """How one declaration relates to the store's record."""

    file: str
    section: str
    status: str  # declared / edited / added / not recorded


def check(recorded: dict | None, files: dict[str, Path] | None = None) -> list[Lock]:
    """Every declaration of ``files`` against the store's record (``store.json`` "declarations")."""
    current = fingerprint(files)
    out = []
    for name, fp in current.items():
        old = (recorded or {}).get(name)
        for section, h in fp["sections"].items():
            if section in NOTES:
                continue
            if old is None:
                status = NOT_RECORDED
            elif section not in old.get("sections", {}):
                status = ADDED
            else:
                status = DECLARED if old["sections"][section] == h else EDITED
            out.append(Lock(name, section, status))
    return out


def status_of(locks: list[Lock], file: str, section: str) -> str:
    """The status of one declaration (``file``'s ``section``) among ``locks``; ``NOT_RECORDED`` if the store holds
    no record of it."""
    for lk in locks:
        if lk.file == file and lk.section == section:
            return lk.status
    return NOT_RECORDED


def summary(locks: list[Lock], file: str, prefix: str = "") -> str:
    """One line on ``file``'s declarations (those starting with ``prefix``): how many were declared
    before the store's first run, and which were edited or added after it."""
    mine = [lk for lk in locks if lk.file == file and lk.section.startswith(prefix)]
    if not mine or all(lk.status == NOT_RECORDED for lk in mine):
        return (f"{file}: the store holds no record of its declarations (made before stores kept one), "
                "so whether they were declared before its first run cannot be checked here")
    by = {s: [lk.section for lk in mine if lk.status == s] for s in (DECLARED, EDITED, ADDED)}
    text = f"{file}: {len(by[DECLARED])} of {len(mine)} declarations unchanged since before the store's first run"
    if by[EDITED]:
        text += f"; EDITED after its first run: {', '.join(by[EDITED])}"
    if by[ADDED]:
        text += f"; ADDED after its first run: {', '.join(by[ADDED])}"
    return text


def size_note(declared_runs: int | None, runs: list[int]) -> str:
    """"" when every compared group has the declared run count, else a sentence saying otherwise."""
    if not declared_runs or not runs or all(n == declared_runs for n in runs):
        return ""
    return (f"answered with {min(runs)}-{max(runs)} runs per condition, not the {declared_runs} declared"
            if min(runs) != max(runs) else
            f"answered with {runs[0]} runs per condition, not the {declared_runs} declared")
