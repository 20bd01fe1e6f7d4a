"""Terrain setups from the command line: bad files exit 2 with one message, `run` writes per-site counts."""
import pytest

from infomarket.store.results import Store

from infomarket.cli import main

GOOD = """
steps = 400
[swarm]
robots = 10
[[swarm.groups]]
behaviour = "naive"
count = 10
[[food]]
x = 200.0
y = 300.0
[[food]]
x = 700.0
y = 100.0
[[obstacles]]
shape = "circle"
x = 600.0
y = 400.0
radius = 30.0
"""


@pytest.mark.parametrize("extra, message", [
    ('[[obstacles]]\nshape = "blob"\n', "obstacles[1]: shape must be one of rect, circle, segment"),
    ('[[obstacles]]\nshape = "rect"\nx0 = 0.0\ny0 = 0.0\nx1 = 5.0\ny1 = 5.0\nr = 1.0\n',
     "obstacles[1].r: unknown key; allowed keys here: shape, x0, x1, y0, y1"),
    ('[[obstacles]]\nshape = "segment"\nx0 = 1.0\ny0 = 1.0\nx1 = 1.0\ny1 = 1.0\n', "two different end points"),
    ('[[obstacles]]\nshape = "circle"\nx = 740.0\ny = 100.0\nradius = 20.0\n',
     "food[1] site at (700.0, 100.0) with radius 50.0 overlaps obstacles[1]"),
    ('[robot]\ncollisions = "yes"\n', "robot.collisions: Input should be a valid boolean"),
])
def test_bad_terrain_file_is_one_clear_error_exit_2(tmp_path, capsys, extra, message):
    path = tmp_path / "bad.toml"
    path.write_text(GOOD + extra)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_run_writes_items_per_site(tmp_path):
    path = tmp_path / "t.toml"
    path.write_text(GOOD.replace("steps = 400", "steps = 3000"))
    out = tmp_path / "out"
    assert main(["run", str(path), "--runs", "2", "--out", str(out), "--workers", "1", "--quiet"]) == 0
    store = Store(out)
    sites, robots = store.sites(), store.robots()
    assert sites.columns.tolist() == ["experiment", "condition", "run", "seed", "site", "kind", "x", "y", "radius",
                                      "items"]
    assert sites.groupby("run").kind.apply(list).tolist() == [["food", "food", "nest"]] * 2
    # every deposit is counted at the one nest and in some robot's items (two independent counters)
    nest = sites[sites.kind == "nest"].set_index("run")["items"]
    assert nest.to_dict() == robots.groupby("run").items_collected.sum().to_dict()
    assert nest.sum() > 0


def test_plane_run_writes_no_sites_table(tmp_path):
    out = tmp_path / "p"
    assert main(["run", "fig2A", "--runs", "1", "--steps", "200", "--out", str(out), "--quiet"]) == 0
    assert Store(out).sites().empty and len(Store(out).robots()) == 25
