"""Obstacles, every site and collisions in the scene, the movie and a real browser (docs/terrain.md)."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import infomarket as im
from infomarket.engine import Simulation
from infomarket.viewer import movie
from infomarket.viewer.frames import scene
from infomarket.viewer.recording import record, write_html

OBSTACLES = [{"shape": "rect", "x0": 400.0, "y0": 350.0, "x1": 500.0, "y1": 550.0},
             {"shape": "circle", "x": 850.0, "y": 150.0, "radius": 40.0},
             {"shape": "segment", "x0": 600.0, "y0": 0.0, "x1": 600.0, "y1": 60.0},
             {"shape": "segment", "x0": 600.0, "y0": 140.0, "x1": 600.0, "y1": 600.0}]


@pytest.fixture(scope="module")
def terrain():
    """100 colliding robots, two food sites, a nest, a rectangle, a circle and a wall with a gap."""
    return im.Experiment.model_validate({
        "name": "terrain_view", "steps": 2000,
        "food": [{"x": 200.0, "y": 300.0}, {"x": 700.0, "y": 100.0}], "nest": {"x": 1000.0, "y": 300.0},
        "obstacles": OBSTACLES, "robot": {"collisions": True, "line_of_sight": True},
        "swarm": {"robots": 100, "groups": [{"behaviour": "naive", "count": 100}]}})


@pytest.fixture(scope="module")
def recording(terrain):
    return record(terrain, 1, steps=1500, every=50)


def test_scene_lists_every_site_and_obstacle(terrain):
    s = scene(Simulation(terrain, seed=1))
    assert [(x["name"], x["x"], x["y"]) for x in s["sites"]] == [
        ("food", 200.0, 300.0), ("food", 700.0, 100.0), ("nest", 1000.0, 300.0)]
    assert s["site_kinds"] == ["food", "nest"]
    assert [o["shape"] for o in s["obstacles"]] == ["rect", "circle", "segment", "segment"]
    assert s["obstacles"][1] == {"shape": "circle", "x": 850.0, "y": 150.0, "radius": 40.0}
    assert s["robot"]["collisions"] is True and s["robot"]["line_of_sight"] is True


def test_contacts_are_discs_closer_than_a_diameter():
    xy = np.array([[0.0, 0.0], [16.0, 0.0], [40.0, 0.0], [56.2, 0.0]])
    # 0-1 touch (16 = 2 r); 2-3 are 16.2 apart (more than 2 r + 0.1)
    assert movie.in_contact(xy, 8.0).tolist() == [True, True, False, False]


def test_movie_draws_the_obstacles(recording, tmp_path):
    path = movie.write_movie(recording, tmp_path / "terrain.gif", max_frames=3)
    with Image.open(path) as gif:
        rgb = np.asarray(gif.convert("RGB")).astype(int)
    grey = np.all(np.abs(rgb - (0x5A, 0x5A, 0x5A)) < 12, axis=-1).sum()
    scale = movie.WIDTH_PX[".gif"] / 1200.0
    solid = (100 * 200 + np.pi * 40**2) * scale**2  # the rectangle and the circle
    assert grey > 0.8 * solid, (grey, solid)


# ------------------------------------------------------------------------------------------ browser
from .test_browser import CHROMEDRIVER, CHROMIUM, driver, js_errors, open_page, wait_for  # noqa: E402,F401 - pytest's fixture and helpers, after this file's own tests

GREY_AND_FOOD = """
const c = document.getElementById('arena'), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
const k = c.width / 1200;
const near = (i, r, g, b, tol) =>
  Math.abs(d[i] - r) < tol && Math.abs(d[i + 1] - g) < tol && Math.abs(d[i + 2] - b) < tol;
let grey = 0;
for (let i = 0; i < d.length; i += 4) if (near(i, 0x5a, 0x5a, 0x5a, 12)) grey++;
const food = (cx, cy) => {  // pixels of the food fill (green at alpha 0.35 on the arena's #f4f4f1)
  let n = 0;
  for (let y = Math.floor((cy - 50) * k); y < (cy + 50) * k; y++)
    for (let x = Math.floor((cx - 50) * k); x < (cx + 50) * k; x++)
      if (near(4 * (y * c.width + x), 174, 215, 172, 14)) n++;
  return n;
};
return [grey, food(200, 300), food(700, 100), k];
"""


@pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER), reason="headless Chromium not installed "
                    "(tools/ci/install-browser.sh)")
def test_browser_shows_obstacles_every_site_and_contacts(driver, recording, tmp_path):  # noqa: F811 - pytest's fixture
    path = write_html(recording, tmp_path / "terrain.html")
    open_page(driver, path.as_uri())
    subtitle = driver.execute_script("return document.getElementById('subtitle').textContent")
    assert "4 obstacles · collisions · line of sight" in subtitle
    grey, food_far, food_near, k = driver.execute_script(GREY_AND_FOOD)
    assert grey > 0.9 * (100 * 200 + np.pi * 40**2) * k * k, grey
    disc = np.pi * 50**2 * k * k
    assert food_far > 0.3 * disc and food_near > 0.3 * disc, (food_far, food_near, disc)
    driver.find_element("id", "play").click()
    wait_for(driver, "infomarketViewer.step >= 1500", what="the replay to reach its end")
    wait_for(driver, "infomarketViewer.contacts > 0", what="robots drawn in contact")
    shot = tmp_path / "viewer-terrain.png"
    driver.save_screenshot(str(shot))
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and shot.stat().st_size > 20_000
    assert not js_errors(driver)
