"""The licence and the citation file a user of the project relies on: CITATION.cff parses and carries what
the Citation File Format 1.2.0 requires (and what a citing paper needs: the version and the paper the
software implements), and every place that names the licence names the same one."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import yaml

import infomarket

REPO = Path(__file__).resolve().parents[1]


def _cff() -> dict:
    return yaml.safe_load((REPO / "CITATION.cff").read_text(encoding="utf-8"))


def test_citation_has_the_keys_cff_1_2_requires():
    cff = _cff()
    assert cff["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors"):  # the format's required keys besides cff-version
        assert cff.get(key), key
    for author in cff["authors"]:
        assert author.get("name") or author.get("family-names"), author  # a person or an entity


def test_citation_names_the_version_users_run():
    """A citation of the software must say which version produced the results."""
    assert str(_cff()["version"]) == infomarket.__version__


def test_citation_references_the_paper_it_implements():
    papers = [r for r in _cff().get("references", []) if r.get("type") == "article"]
    assert len(papers) == 1
    paper = papers[0]
    assert "information market" in paper["title"]
    assert paper["doi"].startswith("10.")
    assert all(a.get("family-names") for a in paper["authors"])


def _spdx_of_contracts() -> set[str]:
    ids = set()
    for sol in (REPO / "contracts").rglob("*.sol"):
        found = re.findall(r"SPDX-License-Identifier:\s*(\S+)", sol.read_text(encoding="utf-8"))
        assert found, f"{sol.name} has no SPDX-License-Identifier"
        ids.update(found)
    return ids


def test_every_place_names_the_same_licence():
    pyproject = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]["license"]
    declared = pyproject if isinstance(pyproject, str) else pyproject["text"]
    licence_file = (REPO / "LICENSE").read_text(encoding="utf-8")
    assert licence_file.splitlines()[0] == f"{declared} License"
    assert "Permission is hereby granted, free of charge" in licence_file  # the MIT text, not only its title
    assert _spdx_of_contracts() == {declared}
    assert _cff()["license"] == declared
