"""The examples of docs/extending.md: they are the files in examples/, and they work."""
import re
from pathlib import Path

import numpy as np
import pytest

import infomarket as im
from infomarket import plugins
from infomarket.ledger import LedgerEvent, replay_events

ROOT = Path(__file__).parents[1]


@pytest.fixture(scope="module", autouse=True)
def examples():
    for name in ("age_liar.py", "equal_split.py", "reputation_outlier.py", "path_follower.py"):
        plugins.load(str(ROOT / "examples" / name))


def test_doc_code_is_the_example_code():
    doc = (ROOT / "docs" / "extending.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", doc, re.S)
    for name in ("age_liar.py", "equal_split.py", "reputation_outlier.py", "path_follower.py"):
        code = (ROOT / "examples" / name).read_text()
        assert code in blocks, f"docs/extending.md does not show examples/{name} as it is"
        assert len(code.strip().splitlines()) <= 20


def test_equal_split_pays_each_seller_the_same():
    events = [LedgerEvent("purchase", 0, 1, 0, 0.0)] * 3 + [LedgerEvent("purchase", 0, 2, 1, 90.0),
                                                          LedgerEvent("deposit", 0)]
    res = replay_events(events, 3, scheme="equal_split")
    assert res.balances == pytest.approx([1.5, 1.25, 1.25])


def test_reputation_outlier_pays_by_the_sellers_records():
    # deposit 1: agreement 3, 3, 3, 1 (the 100 deg sale is alone), every reputation 1/2 (newcomers):
    # weights 1.5, 1.5, 1.5, 0.5 of 5, shares of 0.5: 0.15, 0.15, 0.15, 0.05; seller 4 is an outlier
    # (0.5 < half of 1.5), so its reputation becomes 1/3 and the others' 2/3
    first = [LedgerEvent("purchase", 0, s, 0, d) for s, d in ((1, 0.0), (2, 5.0), (3, 10.0), (4, 100.0))]
    # deposit 2: sellers 1 and 4 agree (weight 2 each) but weigh 2 x 2/3 and 2 x 1/3: 1/3 and 1/6 of 0.5;
    # 2/3 is exactly half the best weight 4/3, not below it, so seller 4 is no outlier this time
    second = [LedgerEvent("purchase", 0, 1, 1, 0.0), LedgerEvent("purchase", 0, 4, 1, 0.0)]
    res = replay_events(first + [LedgerEvent("deposit", 0)] + second + [LedgerEvent("deposit", 0)], 5,
                        scheme="reputation_outlier")
    assert res.balances == pytest.approx([2.0, 1 + 0.15 + 1 / 3, 1.15, 1.15, 1 + 0.05 + 1 / 6])
    assert res.record["rep_reduced"].tolist() == [0, 0, 0, 0, 1]
    assert res.record["rep_settled"].tolist() == [0, 2, 1, 1, 2]


def test_age_liar_sells_far_more_than_an_honest_robot():
    cfg = im.load_experiment(ROOT / "examples" / "age_liar.toml").with_overrides(steps=3000)
    res = im.simulate(cfg, seed=3, record_events=True)
    ev = res.events[res.events.kind == "purchase"]
    liar = int(res.robots.index[res.robots.behaviour == "age_liar"][0])
    sales = ev.groupby("seller").size().reindex(range(25), fill_value=0)
    assert sales[liar] > 3 * np.median(sales.drop(liar))
    assert set(ev[ev.seller == liar].age) == {0}  # every sale claimed age 0
    # equal split conserves money like every scheme
    assert res.totals["wealth"] + res.totals["pots"] == pytest.approx(25 + res.robots.items_collected.sum())


def test_plugins_are_checked_by_the_validator(tmp_path):
    bad = tmp_path / "x.toml"
    bad.write_text('plugins = ["missing.py"]\n[swarm]\nrobots = 1\n[[swarm.groups]]\nbehaviour = "naive"\ncount = 1\n')
    with pytest.raises(im.ConfigError, match="missing.py"):
        im.load_experiment(bad)


def test_registering_twice_needs_replace():
    def sell(w, me, site):
        return False, 0.0, 0.0, 0

    im.register_behaviour("tmp_silent", buy="naive", sell=sell, honest=False)
    with pytest.raises(ValueError, match="already registered"):
        im.register_behaviour("tmp_silent", buy="naive", sell=sell, honest=False)
    im.register_behaviour("tmp_silent", buy="naive", sell=sell, honest=False, replace=True)


def test_path_follower_takes_a_plain_vector_as_a_path_via_the_seller():
    """Two robots on the plane, 20 apart, both facing +x: the seller believes food is 50 ahead; the
    buyer (entry invalid, old) installs the path (seller's position, food) = (20, 0), (70, 0)."""
    from infomarket.engine import Simulation
    from infomarket.engine.world import FOOD

    cfg = im.config.validate({"steps": 10, "swarm": {"robots": 2, "groups": [{"behaviour": "path_follower",
                                                                              "count": 2}]},
                              "robot": {"noise_sd": 0.0, "bias_mean": 0.0, "bias_sd": 0.0}})
    sim = Simulation(cfg, seed=1)
    w = sim.world
    w.pos[:] = [(300.0, 300.0), (320.0, 300.0)]
    w.hdir[:] = [(1.0, 0.0), (1.0, 0.0)]
    w.tab_age[0, FOOD] = 100
    w.tab_vec[1, FOOD] = (50.0, 0.0)
    w.tab_valid[1, FOOD] = True
    w.tab_age[1, FOOD] = 1
    w.state[1] = 1  # seeking food
    sim.step(1)
    assert w.path_count[0, FOOD] == 1 and w.tab_valid[0, FOOD]
    # world points: buyer position + (entry, waypoint) in its frame (heading unchanged: it moved along +x
    # or not at all, after the purchase's stop)
    c, s = w.hdir[0]
    pts = [w.tab_vec[0, FOOD], w.path_vec[0, FOOD, 0]]
    world = [(w.pos[0, 0] + c * x - s * y, w.pos[0, 1] + s * x + c * y) for x, y in pts]
    np.testing.assert_allclose(world, [(320.0, 300.0), (370.0, 300.0)], atol=1e-9)
