import pandas as pd
import pytest

from infomarket.analysis.frames import Frames, MissingDataError, composition, experiment, require
from infomarket.store import Store, StoreError



def test_a_missing_folder_is_a_store_error(tmp_path):
    with pytest.raises(StoreError, match="no such folder"):
        Frames.of(tmp_path / "nowhere")


def test_a_folder_without_store_json_is_a_store_error(tmp_path):
    (tmp_path / "x.txt").write_text("hello")
    with pytest.raises(StoreError, match="not an infomarket results store"):
        Frames.of(tmp_path)


def test_an_empty_store_gives_empty_tables(tmp_path):
    f = Frames.of(Store(tmp_path / "s").create())
    assert f.robots.empty and f.history.empty and f.runs.empty
    assert f.meta["format"] == 1


def test_frames_accept_dataframes_and_dicts(paper_frames):
    robots = paper_frames.robots
    assert Frames.of(robots).robots is robots
    assert Frames.of({"robots": robots, "history": None}).history.empty
    with pytest.raises(TypeError):
        Frames.of({"robot": robots})


def test_require_names_what_is_missing(paper_frames):
    robots = experiment(paper_frames.robots, "fig2A")
    assert len(require(robots, "fig2A", ("items_collected",))) == len(robots) == 6 * 25
    with pytest.raises(MissingDataError, match="no fig3A rows"):
        require(robots, "fig3A")
    with pytest.raises(MissingDataError, match="missing columns rotation_angle"):
        require(robots, "fig2A", ("rotation_angle",))
    assert experiment(pd.DataFrame(), "fig2A").empty


@pytest.mark.parametrize("part, label", [
    ("fig2A", "25 naive"),
    ("fig2B", "24 naive + 1 saboteur"),
    ("fig3C", "20 sceptical + 5 scaboteurs"),
])
def test_composition_reads_the_swarm_like_the_paper(part, label, paper_frames):
    assert composition(experiment(paper_frames.robots, part)) == label
