"""Terrain setups from the command line: bad files exit 2 with one message; a plane run writes no per-site
counts (a terrain run's: tests/store/test_run_store.py)."""
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


def test_plane_run_writes_no_sites_table(tmp_path):
    out = tmp_path / "p"
    assert main(["run", "fig2A", "--runs", "1", "--steps", "200", "--out", str(out), "--quiet"]) == 0
    assert Store(out).sites().empty and len(Store(out).robots()) == 25
