"""Synthetic stores shared by the analysis tests (built once per session: they are read-only)."""
from __future__ import annotations

import pytest

from infomarket.analysis.frames import Frames
from infomarket.analysis.report import build_report

from .synthetic import paper_like, write_store


@pytest.fixture(scope="session")
def paper_store(tmp_path_factory):
    return write_store(tmp_path_factory.mktemp("paper") / "store", paper_like())


@pytest.fixture(scope="session")
def paper_report(paper_store, tmp_path_factory):
    """``build_report`` of the paper-like store, drawn once (every figure): (the report, its folder, the lines
    it echoed).  For tests that only read what it wrote."""
    out, lines = tmp_path_factory.mktemp("paper-report"), []
    return build_report(paper_store, out, echo=lines.append), out, lines


@pytest.fixture(scope="session")
def paper_frames(paper_store):
    return Frames.of(paper_store)


@pytest.fixture(scope="session")
def equal_wealth_store(tmp_path_factory):
    """Honest and Byzantine robots share one wealth distribution in Figs. 3-4."""
    return write_store(tmp_path_factory.mktemp("equal") / "store", paper_like(honest_richer=False))
