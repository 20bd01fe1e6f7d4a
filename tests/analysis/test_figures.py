import re

import matplotlib.image as mpimg
import numpy as np
import pytest
from matplotlib.figure import Figure

from infomarket import analysis
from infomarket.analysis import figures
from infomarket.analysis.frames import MissingDataError


def assert_not_blank(path):
    assert path.stat().st_size > 5_000, path
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 500
    assert img[..., :3].std() > 0.05, f"{path} is (nearly) blank"
    assert (np.abs(img[..., :3] - img[0, 0, :3]).sum(axis=-1) > 0.1).mean() > 0.02  # ink, not background


PANELS = {"fig2": 4, "fig3": 3, "fig4": 3, "fig5": 2, "fig6": 2, "fig7": 2}  # as in the paper


@pytest.mark.parametrize("spec", figures.FIGURES, ids=lambda s: s.name)
def test_each_figure_renders_to_a_non_blank_png_and_a_vector_file(spec, paper_frames, tmp_path):
    fig = spec.draw(paper_frames)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == PANELS[spec.name]
    png, vector = figures.save(fig, tmp_path, spec.name)
    assert_not_blank(png)
    assert vector.suffix == ".svg" and vector.read_text().lstrip().startswith("<?xml")


def test_fig3_annotates_the_mann_whitney_p_value_on_each_panel(paper_frames):
    fig = analysis.fig3(paper_frames.robots)
    for ax in fig.axes:  # under the panel, where no whisker can cross it (it did in fig3.png panel C)
        assert "Mann-Whitney" in ax.get_xlabel() and "p = " in ax.get_xlabel()
        assert "run-level signed-rank, 12 runs" in ax.get_xlabel()


def test_fig6_shows_pearson_r(paper_frames):
    fig = analysis.fig6(paper_frames.robots)
    assert sum("Pearson r = -0." in ax.get_xlabel() for ax in fig.axes) == 2


def test_box_plots_follow_the_paper_convention(paper_frames):
    """Whiskers at 1.5 IQR, outliers as black diamonds, honest blue and Byzantine red."""
    ax = analysis.fig2(paper_frames.robots).axes[1]  # 2B: honest and saboteur
    faces = [p.get_facecolor()[:3] for p in ax.patches]
    assert len(faces) == 2
    assert faces[0][2] > faces[0][0] and faces[1][0] > faces[1][2]  # blue, then red
    fliers = [ln for ln in ax.lines if ln.get_marker() == "D"]
    assert fliers and all(ln.get_markerfacecolor() == "black" for ln in fliers)


def test_a_figure_without_data_raises_missing_data(paper_frames):
    with pytest.raises(MissingDataError):
        analysis.fig2(paper_frames.robots.iloc[0:0])
    with pytest.raises(MissingDataError):
        analysis.fig5(paper_frames.history.iloc[0:0])
    with pytest.raises(MissingDataError):
        analysis.fig7(paper_frames.robots[paper_frames.robots.experiment != "fig7"])


def test_a_figure_with_some_panels_marks_the_others_as_missing(paper_frames):
    fig = analysis.fig2(paper_frames.robots[paper_frames.robots.experiment == "fig2A"])
    notes = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert sum("no fig2" in n for n in notes) == 3


def test_fig5_takes_honesty_from_the_robots_table_when_the_history_lacks_it(paper_frames):
    history = paper_frames.history.drop(columns=["honest", "behaviour"])
    fig = analysis.fig5(history, paper_frames.robots)
    assert len(fig.axes[0].lines) == 2
    with pytest.raises(MissingDataError, match="no honest column"):
        analysis.fig5(history)


@pytest.mark.parametrize("spec", figures.FIGURES, ids=lambda s: s.name)
def test_no_label_is_cut_or_overlaps_another_or_is_crossed_by_data(spec, paper_frames):
    from .layout import problems

    assert problems(spec.draw(paper_frames)) == []


@pytest.mark.parametrize("spec", [s for s in figures.FIGURES if s.name != "fig5"], ids=lambda s: s.name)
def test_every_panel_names_its_run_count(spec, paper_frames):
    """Fig. 5 names its runs in each curve's legend entry instead (two curves per panel)."""
    fig = spec.draw(paper_frames)
    for ax in fig.axes:
        assert re.search(r"\b\d+(-\d+)? runs?\b", ax.get_title(loc="left")), ax.get_title(loc="left")


def test_fig5_names_its_runs_in_the_legend_and_its_reference_line(paper_frames):
    fig = analysis.fig5(paper_frames.history, paper_frames.robots)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert sum(bool(re.search(r"\(\d+ runs\)", lab)) for lab in labels) == 2
    assert any(lab.startswith("equal share") for lab in labels)


def test_reference_lines_are_in_the_legend_with_their_own_style(paper_frames):
    """Not colour alone: the equal-share line (Figs. 3-4) is dashed and named; Theta (Fig. 7) dotted."""
    for fig, label, style in ((analysis.fig3(paper_frames.robots), "equal share (4 %)", "--"),
                              (analysis.fig7(paper_frames.robots), "Theta = 30 deg", ":")):
        handles = {h.get_label(): h for h in fig.legends[0].legend_handles}
        assert label in handles and handles[label].get_linestyle() == style


def test_fig7_marks_each_angle_with_its_test(paper_frames):
    """Panel B: one-sided Mann-Whitney of staking over no staking at each angle above Theta, Holm over
    them; panel A: TOST within 10 % of the no-staking median, Holm over all angles."""
    runs = figures.metrics.swarm_throughput(paper_frames.robots)
    b = figures.fig7_tests(runs, 3)
    assert list(b.angle) == sorted(a for a in runs[runs.byzantines == 3].rotation_angle.unique() if a > 30)
    # Holm by hand: the i-th smallest p times (k - i + 1), running maximum
    p = np.sort(b.p.to_numpy())
    k = len(p)
    want = np.maximum.accumulate(np.minimum(1, (k - np.arange(k)) * p))
    assert np.allclose(np.sort(b.p_holm.to_numpy()), want)
    a = figures.fig7_tests(runs, 1)
    assert len(a) == runs[runs.byzantines == 1].rotation_angle.nunique()
    assert (a.margin > 0).all()
    fig = analysis.fig7(paper_frames.robots)
    marks = [t.get_text() for t in fig.axes[1].texts]
    assert marks.count("*") == int(b.significant.sum()) and len(marks) == len(b)
    assert f"staking higher at {int(b.significant.sum())} of {len(b)} angles" in fig.axes[1].get_title(loc="left")
    assert "equivalent within ±10 %" in fig.axes[0].get_title(loc="left")


def test_fig7_marks_a_missing_box(paper_frames):
    robots = paper_frames.robots
    gone = (robots.experiment == "fig7") & (robots.market == "staking") & (robots.rotation_angle == 40) \
        & (robots.byzantines == 3)
    assert gone.any()
    fig = analysis.fig7(robots[~gone])
    assert "1 box MISSING" in fig.axes[1].get_title(loc="left")
    assert any(t.get_text() == "missing: staking" for t in fig.axes[1].texts)
