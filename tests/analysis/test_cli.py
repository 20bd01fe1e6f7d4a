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
