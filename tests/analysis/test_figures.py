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
    for ax in fig.axes:
        assert any("Mann-Whitney" in t.get_text() and "p = " in t.get_text() for t in ax.texts)
        assert any("run-level signed-rank, 12 runs" in t.get_text() for t in ax.texts)


def test_fig6_shows_pearson_r(paper_frames):
    fig = analysis.fig6(paper_frames.robots)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert sum("Pearson r = -0." in t for t in texts) == 2


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
