"""Issue 21, the viewer's commands: replay writes HTML only into an HTML file, --quiet is quiet."""
from __future__ import annotations

import os

import pytest

from infomarket.cli import main


@pytest.mark.parametrize("name,hint", [("x.pdf", ""), ("x", ""), ("x.mp4", "--movie"), ("x.HTML.txt", "")])
def test_replay_refuses_an_out_file_that_is_not_html(name, hint, tmp_path, capsys):
    out = tmp_path / name
    assert main(["replay", "fig2B", "--steps", "5", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"infomarket: error: --out {out}: the HTML replay is written to a .html") and hint in err
    assert os.listdir(tmp_path) == []


def test_replay_quiet_prints_nothing(tmp_path, capsys):
    out = tmp_path / "x.HTML"
    assert main(["replay", "fig2B", "--steps", "20", "--every", "10", "--out", str(out), "--quiet"]) == 0
    got = capsys.readouterr()
    assert got.out == "" and got.err == ""
    assert out.read_text().startswith("<!DOCTYPE html>") or "<html" in out.read_text()[:500]


def test_view_takes_quiet():
    from infomarket.cli import build_parser

    args = build_parser().parse_args(["view", "fig2B", "--quiet"])
    assert args.quiet is True
