"""No history in the code: no issue numbers, dates or times of day in src/ or the Makefile (they belong
in docs/ and in commit messages).  What is legitimately data is allowed: a declared study's record of
amendments and deviations (``[[amendments]]`` / ``[[deviations]]``, analysis.study), and values that stores
have already fingerprinted (changing their text would flag a rule as edited in every store made since)."""
from __future__ import annotations

import re
from pathlib import Path

import infomarket

PACKAGE = Path(infomarket.__file__).parent
ROOT = PACKAGE.parents[1]
HISTORY = re.compile(r"\bissues? ?#?\d+|\b20\d\d-\d\d-\d\d\b|\b\d{1,2}:\d\d UTC\b", re.IGNORECASE)
TEXT = (".py", ".toml", ".md", ".txt", ".cfg", ".ini")
RECORDS = ("[[amendments]]", "[[deviations]]")

#: values stores have fingerprinted (store.declarations): the terrain questions' `revised` notes
FINGERPRINTED = {"analysis/terrain_questions.toml": {"revised"}}
#: files allowed to carry history outside records (none: every file is kept clean); path -> why
ELSEWHERE: dict[str, str] = {}


def history_lines(text: str, toml: bool = False, fingerprinted: set[str] = frozenset()) -> list[int]:
    """Lines that carry an issue number, a date or a time of day, outside a TOML record table and the
    ``fingerprinted`` keys."""
    out, in_record = [], False
    for n, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if toml and stripped.startswith("["):
            in_record = stripped.split("#")[0].strip() in RECORDS
        if toml and (in_record or stripped.split("=")[0].strip() in fingerprinted):
            continue
        if HISTORY.search(line):
            out.append(n)
    return out


def test_the_finder_finds_each_kind_and_spares_the_record():
    assert history_lines("a  # issue 24\nb = 1\n# 2026-11-24\nstop at 12:40 UTC\nIssue #7") == [1, 3, 4, 5]
    assert history_lines("the tissue 3 times\nversion 2026.1") == []
    toml = ('# AMENDED 2026-11-24\n[study]\nx = "issue 3"\n[[amendments]]\ndate = "2026-11-24 11:18 UTC"\n'
            'why = "see issue 3"\n[questions.a]\nrevised = "issue 24: ..."\nnote = "issue 9"')
    assert history_lines(toml, toml=True) == [1, 3, 8, 9]
    assert history_lines(toml, toml=True, fingerprinted={"revised"}) == [1, 3, 9]


def test_no_issue_number_or_date_in_src():
    found = {}
    for path in sorted(PACKAGE.rglob("*")):
        rel = str(path.relative_to(PACKAGE))
        if path.suffix not in TEXT or rel in ELSEWHERE or "__pycache__" in path.parts:
            continue
        lines = history_lines(path.read_text(encoding="utf-8"), path.suffix == ".toml", FINGERPRINTED.get(rel, set()))
        if lines:
            found[rel] = lines
    assert found == {}


def test_the_allowed_files_elsewhere_still_need_it():
    """An entry of ELSEWHERE whose file no longer carries history is stale: take it out."""
    stale = [rel for rel in ELSEWHERE if not history_lines((PACKAGE / rel).read_text(encoding="utf-8"),
                                                           rel.endswith(".toml"))]
    assert stale == []


def test_no_history_in_the_makefile():
    assert history_lines((ROOT / "Makefile").read_text()) == []
