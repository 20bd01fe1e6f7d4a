"""Issue 21: the analysis commands as a new user meets them."""
import sys

from infomarket.cli import main

from .synthetic import paper_like, write_store


def test_sensitivity_help_shows_a_plain_percent_sign(procs):
    out = procs.run([sys.executable, "-m", "infomarket.cli", "sensitivity", "--help"], check=True).stdout
    assert "95 % intervals" in " ".join(out.split()) and "%%" not in out


def test_figures_quiet_prints_nothing(tmp_path, capsys):
    store = write_store(tmp_path / "s", paper_like(), only=("fig2",))
    assert main(["figures", str(store.root), "--out", str(tmp_path / "f"), "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    assert (tmp_path / "f" / "report.md").exists()
