from infomarket import analysis
from infomarket.analysis import build_report, collect_provenance
from infomarket.analysis.figures import save

from .synthetic import paper_like, write_store


def test_report_has_every_figure_the_table_and_provenance(paper_report):
    report, out, lines = paper_report
    for name in ("fig2", "fig3", "fig4", "fig5", "fig6", "fig7"):
        assert (out / f"{name}.png").stat().st_size > 5_000
        assert (out / f"{name}.svg").exists()
        assert any(line.startswith(f"{name}: wrote") for line in lines)
    md = (out / "report.md").read_text()
    html = (out / "report.html").read_text()
    for name in ("fig2", "fig7"):
        assert f"]({name}.png)" in md and f"src='{name}.png'" in html
    assert "## Paper vs this store" in md
    assert md.count("| pass |") == len(report.table)
    assert html.count("<tr class=\"pass\">") == len(report.table)
    assert "cafefig2A" in md and "cafefig7" in html        # configuration hashes
    assert "package versions" in md and "0.1.0" in md
    assert "| fig2A | 6 | 1 | 15000 |" in md                  # runs, conditions, steps per experiment
    assert "6 distinct, 1000 .. 1005" in md                   # seeds
    assert "report date" in md and "store created" in md


def test_a_store_without_some_experiments_skips_their_figures(tmp_path):
    store = write_store(tmp_path / "s", paper_like(), only=("fig2", "fig3"))
    lines = []
    report = build_report(store, tmp_path / "out", echo=lines.append)
    assert [r.name for r in report.figures if r.files] == ["fig2", "fig3"]
    skipped = [line for line in lines if "skipped" in line]
    assert len(skipped) == 4 and all("\n" not in line for line in skipped)
    md = (tmp_path / "out" / "report.md").read_text()
    assert "*Skipped: no fig5 rows in the store.*" in md
    assert not (tmp_path / "out" / "fig5.png").exists()
    assert report.counts()["no data"] > 0


def test_a_pdf_can_replace_the_svg(paper_frames, tmp_path):
    robots = paper_frames.robots[paper_frames.robots.experiment.str.startswith("fig2")]
    report = build_report({"robots": robots}, tmp_path, vector="pdf")
    assert (tmp_path / "fig2.pdf").read_bytes().startswith(b"%PDF")
    assert [r.name for r in report.figures if r.files] == ["fig2"]
    assert "fig2](fig2.png)" in (tmp_path / "report.md").read_text()


def test_same_store_gives_identical_figures(paper_frames, tmp_path):
    """The fig6 band is a bootstrap: seeded, so the files are byte for byte the same."""
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        out.mkdir()
        save(analysis.fig6(paper_frames.robots), out, "fig6")
    assert (a / "fig6.svg").read_bytes() == (b / "fig6.svg").read_bytes()
    assert (a / "fig6.png").read_bytes() == (b / "fig6.png").read_bytes()


def test_provenance_counts_runs_per_experiment(paper_frames):
    p = collect_provenance(paper_frames).experiments.set_index("experiment")
    assert p.loc["fig7", "runs"] == 2 * 2 * 10 * 8 and p.loc["fig7", "conditions"] == 40
    assert p.loc["fig7", "config hashes"] == "cafefig7"
    assert p.loc["fig5", "status"] == "ok: 4"
