"""The model's semantics ship with the project: nothing points outside the repository, and every
``docs/model.md §N`` cited anywhere names a section that docs/model.md has."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

from .procs import Procs

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "docs" / "model.md"
#: Spelled in pieces so that this file does not match itself.
OUTSIDE = ("MODEL" + ".md", ".." + "/shared", "/work" + "/shared")
#: Files that may still point outside, relative to the repository root.  The engine and analysis
#: folders are another engineer's (issue 20, item 4 lists the one sed that converts them); remove each
#: file once converted: a listed file that no longer needs it fails the test, so the list only shrinks.
#: ``.ci/run`` is the CI harness's entry point (a comment on how CI lays out its checkout), not the
#: project's; the project must not depend on what it mentions.
STILL_ALLOWED: frozenset = frozenset()

CITATION = re.compile(r"docs/model\.md §(\d+)(?:\s*[-–]\s*§?(\d+))?")
SECTION = re.compile(r"^## (\d+)\. \S", re.MULTILINE)


def repository_files() -> dict[str, str]:
    """Every text file of the checkout that git would commit (tracked or new), by relative path."""
    git = shutil.which("git")
    if git and (ROOT / ".git").exists():
        with Procs() as procs:
            listed = procs.run([git, "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                               check=True).stdout.split("\0")
        paths = [ROOT / p for p in listed if p]
    else:  # an unpacked source tree
        skip = {".git", ".venv", "node_modules", "__pycache__", ".pytest_cache"}
        paths = [p for p in ROOT.rglob("*") if p.is_file() and not skip & set(p.relative_to(ROOT).parts)]
    out = {}
    for p in paths:
        try:
            data = p.read_bytes()
        except OSError:  # listed but deleted in the working tree
            continue
        if b"\0" not in data:
            out[p.relative_to(ROOT).as_posix()] = data.decode("utf-8", "replace")
    return out


def sections() -> set[int]:
    return {int(n) for n in SECTION.findall(MODEL.read_text())}


def cited(text: str) -> set[int]:
    out: set[int] = set()
    for first, last in CITATION.findall(text):
        out.update(range(int(first), int(last or first) + 1))
    return out


def test_the_citation_pattern_reads_single_sections_and_ranges():
    assert cited("see docs/model.md §3, docs/model.md §2-4 and (docs/model.md §10).") == {2, 3, 4, 10}
    assert cited("docs/model.md §1–§2") == {1, 2} and cited("docs/model.md, §4") == set()


def test_the_model_page_numbers_its_sections_one_to_ten():
    assert sorted(sections()) == list(range(1, 11))


def test_nothing_points_outside_the_repository():
    files = repository_files()
    assert "docs/model.md" in files and "tests/test_model_doc.py" in files  # the walk sees the repository
    found = sorted(f"{path}: {needle}" for path, text in files.items() if path not in STILL_ALLOWED
                   for needle in OUTSIDE if needle in text)
    assert not found, "point at docs/model.md (or a file in this repository) instead:\n" + "\n".join(found)


def test_the_still_allowed_list_only_names_files_that_need_it():
    files = repository_files()
    stale = sorted(p for p in STILL_ALLOWED if not any(n in files.get(p, "") for n in OUTSIDE))
    assert not stale, f"no longer points outside (or gone): remove from STILL_ALLOWED: {stale}"


def test_every_cited_section_exists():
    have = sections()
    missing = sorted(f"{path}: §{n}" for path, text in repository_files().items() for n in cited(text) - have)
    assert not missing, f"docs/model.md has sections {sorted(have)}; cited but missing:\n" + "\n".join(missing)


def test_the_model_page_refers_to_its_own_sections_only():
    have = sections()
    assert {int(n) for n in re.findall(r"§(\d+)", MODEL.read_text())} <= have
