import errno
import os
from pathlib import Path

import pytest

from infomarket.cli import main

from .synthetic import paper_like, write_store


def test_figures_command_writes_the_report_with_a_line_per_figure(tmp_path, capsys):
    store = write_store(tmp_path / "store", paper_like(), only=("fig2", "fig6"))
    assert main(["figures", str(store.root), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "fig2: wrote fig2.png, fig2.svg" in out and "fig6: wrote fig6.png, fig6.svg" in out
    assert "fig5: skipped (no fig5 rows in the store)" in out
    assert "paper vs this store: 9 pass, 0 fail, 0 inconclusive, 16 no data" in out
    assert (tmp_path / "out" / "report.html").exists()


def test_figures_on_a_missing_store_exits_2_with_a_message(tmp_path, capsys):
    assert main(["figures", str(tmp_path / "nope"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "nope: no such folder" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_figures_refuses_an_out_that_is_a_file(paper_store, tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    assert main(["figures", str(paper_store.root), "--out", str(tmp_path / "file")]) == 2
    assert "not a directory" in capsys.readouterr().err


def _never(*args, **kwargs):
    pytest.fail("read the store's tables before checking --out")


def _read_only(*args, **kwargs):
    raise OSError(errno.EROFS, os.strerror(errno.EROFS))


@pytest.mark.parametrize("where", ["read-only", "under a file"])
def test_figures_checks_its_out_before_reading_the_store(where, paper_store, tmp_path, capsys, monkeypatch):
    """A big store takes a while to read: an --out that cannot be written is refused first."""
    import tempfile

    from infomarket.analysis.frames import Frames

    out = tmp_path / "out"
    if where == "read-only":
        monkeypatch.setattr(tempfile, "TemporaryFile", _read_only)
    else:
        (tmp_path / "file").write_text("x")
        out = tmp_path / "file" / "out"
    monkeypatch.setattr(Frames, "of", _never)
    assert main(["figures", str(paper_store.root), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error: --out") == 1 and "Traceback" not in err, err


def test_figures_on_a_full_disk_leave_no_part_of_a_new_set(paper_store, tmp_path, capsys, monkeypatch):
    """The third figure's write fails (a full disk): the folder keeps the older report whole, with no new
    figure beside it and no staging folder left; the error is one line, exit 2."""
    from matplotlib.figure import Figure

    out = tmp_path / "out"
    out.mkdir()
    older = {name: f"older {name}".encode() for name in ("fig2.png", "fig2.svg", "report.md", "notes.txt")}
    for name, text in older.items():
        (out / name).write_bytes(text)
    savefig = Figure.savefig

    def full_disk(self, fname, *args, **kwargs):
        if Path(fname).name.startswith("fig4"):  # fig2, fig3, then fig4: the third figure
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(fname))
        return savefig(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", full_disk)
    assert main(["figures", str(paper_store.root), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error: ") == 1 and "No space left" in err and "Traceback" not in err, err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == older


def test_figures_prints_the_paths_it_leaves(paper_store, tmp_path, capsys):
    """The files are drawn elsewhere and moved in: the paths printed and returned are those in --out."""
    from infomarket.analysis.report import build_report

    out = tmp_path / "out"
    report = build_report(paper_store, out, echo=print)
    printed = capsys.readouterr().out.splitlines()[-1]
    assert printed == f"wrote {out / 'report.md'}, {out / 'report.html'}"
    files = report.files + [f for r in report.figures for f in r.files]
    assert files and all(f.parent == out and f.is_file() for f in files)
    assert sorted(p.name for p in out.iterdir()) == sorted(f.name for f in files)
