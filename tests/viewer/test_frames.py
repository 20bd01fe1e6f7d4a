"""Frames: the binary encoding round-trips, and every column says what the engine's arrays say."""
from __future__ import annotations

import numpy as np
import pytest

import infomarket as im
from infomarket.engine.world import headings
from infomarket.viewer import frames as fr


@pytest.fixture(scope="module")
def running(fig2b):
    sim = im.Simulation(fig2b, 5, record_events=True)
    sim.step(1500)
    return sim


@pytest.fixture(scope="module")
def sceptics():
    sim = im.Simulation(im.load_experiment("fig2D"), 3, record_events=True)
    sim.step(1500)
    return sim


def test_layout_is_aligned_for_typed_array_views():
    offset = 8 * len(fr.HEADER)
    for _, t in fr.COLUMNS:
        size = np.dtype(t).itemsize
        assert offset % size == 0
        offset += 7 * size  # any robot count, here an odd one
    assert fr.frame_size(7) == offset
    assert fr.frame_size(1000) <= 50_000  # what 1 000 robots cost per frame


def test_round_trip_matches_the_world(running):
    w = running.world
    f = fr.decode(fr.encode(running), 25)
    assert f.step == running.clock == 1500
    np.testing.assert_allclose(f.columns["x"], w.pos[:, 0], rtol=1e-6)
    np.testing.assert_allclose(f.columns["heading"], headings(w), rtol=1e-6)
    np.testing.assert_allclose(f.columns["wealth"], w.balance, rtol=1e-6)
    np.testing.assert_array_equal(f.columns["items"], w.items)
    np.testing.assert_array_equal(f.columns["state"], w.state)
    flags = f.columns["flags"]
    np.testing.assert_array_equal((flags & fr.CARRYING) > 0, w.carrying)
    np.testing.assert_array_equal((flags & fr.NEST_VALID) > 0, w.tab_valid[:, 1])
    np.testing.assert_array_equal((flags & fr.LAST_FOOD) > 0, w.last_site == 0)
    np.testing.assert_array_equal((flags & fr.LAST_NEST) > 0, w.last_site == 1)
    assert not np.any((flags & fr.LAST_FOOD) & (flags & fr.LAST_NEST))
    honest = fr.honest_mask(running)
    assert honest.sum() == 24
    assert f.header["items_honest"] == w.items[honest].sum()
    assert f.header["wealth_byzantine"] == pytest.approx(w.balance[~honest].sum())
    with pytest.raises(ValueError, match="25 robots"):
        fr.decode(fr.encode(running)[:-1], 25)


def test_a_robot_that_just_sensed_a_site_believes_it_is_there(running):
    """The believed position is the table vector taken to the world frame: an entry refreshed by sensing
    in the last step (age 1: set at 0, then aged by the move) points at the robot's target point in
    that site, up to one step of odometry noise, so inside the site's disc."""
    f = fr.decode(fr.encode(running), 25)
    cfg = running.config
    checked = 0
    for k, (site, name) in enumerate(((cfg.food, "food"), (cfg.nest, "nest"))):
        fresh = (running.world.tab_age[:, k] == 1) & running.world.tab_valid[:, k]
        d = np.hypot(f.columns[f"{name}_x"][fresh] - site.x, f.columns[f"{name}_y"][fresh] - site.y)
        assert np.all(d <= site.radius + 0.5)
        checked += int(fresh.sum())
    assert checked > 0


def test_scene_names_behaviours_and_layout(running):
    s = fr.scene(running)
    assert s["n"] == 25 and s["seed"] == 5 and s["scheme"] == "delayed"
    assert s["behaviours"] == [{"name": "naive", "honest": True}, {"name": "saboteur", "honest": False}]
    assert s["sites"][0]["name"] == "food" and s["sites"][1]["x"] == running.config.nest.x
    assert [c for c, _ in s["columns"]] == [c for c, _ in fr.COLUMNS]
    np.testing.assert_allclose(s["bias"], running.world.bias, atol=1e-5)


def test_detail_lists_a_sceptics_pending_information_and_trades(sceptics):
    w = sceptics.world
    i = int(np.argmax(w.pend_count.sum(axis=1)))
    assert w.pend_count[i].sum() > 0, "some sceptic has unconfirmed information after 1500 steps"
    d = fr.robot_detail(sceptics, i)
    assert d["id"] == i and d["behaviour"] in ("sceptical", "scaboteur")
    assert len(d["pending"]) == w.pend_count[i].sum()
    assert {p["seller"] for p in d["pending"]} <= set(range(25)) - {i}
    assert len(d["open_transactions"]) == w.tx_count[i]
    steps = [e["step"] for e in d["events"]]
    assert steps == sorted(steps, reverse=True) and len(steps) <= fr.LAST_EVENTS
    assert all(i in (e["buyer"], e["seller"]) for e in d["events"])


def test_last_events_are_found_however_long_the_log(running):
    """The backward scan in chunks finds the same events as a full pass."""
    w = running.world
    k = int(w.ev_count[0])
    for i in range(25):
        mine = np.nonzero((w.ev_buyer[:k] == i) | (w.ev_seller[:k] == i))[0][::-1][:fr.LAST_EVENTS]
        got = fr._last_events(w, i, fr.LAST_EVENTS)
        assert [e["step"] for e in got] == w.ev_step[mine].tolist()
