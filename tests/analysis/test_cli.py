import errno
import os
from pathlib import Path

import pytest

from infomarket.cli import main

from ..refusals import never, refused
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


def _read_only(*args, **kwargs):
    raise OSError(errno.EROFS, os.strerror(errno.EROFS))


@pytest.mark.parametrize("where, words", [("read-only", ("--out", "Read-only")),
                                          ("under a file", ("--out", "not a folder")),
                                          ("a name too long", ("too long",))])
def test_figures_checks_its_out_before_reading_the_tables_and_creates_nothing(where, words, paper_store, tmp_path,
                                                                              capsys, monkeypatch):
    """A big store takes a while to read: an --out that cannot be written is refused first, and the check
    leaves no folder behind."""
    import tempfile

    from infomarket.analysis.frames import Frames

    out = tmp_path / "new" / "out"
    if where == "read-only":
        monkeypatch.setattr(tempfile, "TemporaryFile", _read_only)
    elif where == "under a file":
        (tmp_path / "file").write_text("x")
        out = tmp_path / "file" / "out"
    else:
        out = tmp_path / ("x" * 300) / "out"
    monkeypatch.setattr(Frames, "of", never)
    refused(capsys, ["figures", str(paper_store.root), "--out", str(out)], *words)
    assert sorted(p.name for p in tmp_path.iterdir()) == (["file"] if where == "under a file" else [])


def test_figures_on_a_damaged_store_create_no_out(paper_store, tmp_path, capsys):
    """The --out check creates nothing, so a store refused after it (here: a damaged table part) leaves no
    empty folder."""
    import shutil

    store = tmp_path / "store"
    shutil.copytree(paper_store.root, store)
    part = sorted((store / "robots").glob("part-*.parquet"))[0]
    part.write_bytes(part.read_bytes()[:100])
    refused(capsys, ["figures", str(store), "--out", str(tmp_path / "out")], "is damaged", "store repair")
    assert not (tmp_path / "out").exists()


def _full_disk_at(name: str, monkeypatch):
    from matplotlib.figure import Figure

    savefig = Figure.savefig

    def full_disk(self, fname, *args, **kwargs):
        if Path(fname).name.lstrip(".").startswith(name):  # the atomic writer's temporary name too
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(fname))
        return savefig(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", full_disk)


@pytest.fixture(scope="module")
def two_figures(tmp_path_factory):
    """A store with the rows of Figs. 2 and 4 only: two figures to draw, the second refused a full disk."""
    return write_store(tmp_path_factory.mktemp("two") / "store", paper_like(), only=("fig2", "fig4"))


def test_figures_on_a_full_disk_leave_the_older_report_whole(two_figures, tmp_path, capsys, monkeypatch):
    """The second figure's write fails (a full disk): the folder keeps the older report whole, with no new
    figure beside it and no staging folder left; the error is one line, exit 2."""
    out = tmp_path / "out"
    out.mkdir()
    older = {name: f"older {name}".encode() for name in ("fig2.png", "fig2.svg", "report.md", "notes.txt")}
    for name, text in older.items():
        (out / name).write_bytes(text)
    _full_disk_at("fig4", monkeypatch)
    refused(capsys, ["figures", str(two_figures.root), "--out", str(out), "--quiet"], "No space left")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == older


def test_figures_on_a_full_disk_leave_no_new_folder(two_figures, tmp_path, capsys, monkeypatch):
    _full_disk_at("fig4", monkeypatch)
    refused(capsys, ["figures", str(two_figures.root), "--out", str(tmp_path / "out"), "--quiet"], "No space left")
    assert list(tmp_path.iterdir()) == []


def test_the_report_names_the_files_it_leaves(paper_report):
    """The files are drawn elsewhere and moved in: the paths echoed and returned are those in the folder."""
    report, out, lines = paper_report
    assert lines[-1] == f"wrote {out / 'report.md'}, {out / 'report.html'}"
    files = report.files + [f for r in report.figures for f in r.files]
    assert files and all(f.parent == out and f.is_file() for f in files)
    assert not [p for p in out.iterdir() if p.name.startswith(".report-")]
