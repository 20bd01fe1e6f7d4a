"""A robot that no neighbour can buy from is asked for no offer, unless its sell rule draws random numbers."""
import numpy as np

import infomarket as im
from infomarket.behaviours.api import own_entry

from ..conftest import make_config


def still_sell(w, me, site):
    return own_entry(w, me, site)


def drawing_sell(w, me, site, rng):
    rng.random()
    return own_entry(w, me, site)


def _alone(behaviour: str, seed: int = 3) -> im.Simulation:
    """Five robots that never communicate (range 0: no robot ever has a neighbour), 3 000 steps."""
    cfg = make_config(robots=5, behaviour=behaviour, steps=3000, robot={"communication_range": 0.0})
    sim = im.Simulation(cfg, seed)
    sim.run()
    return sim


def test_a_seller_without_neighbours_is_not_asked_when_asking_draws_nothing():
    im.register_behaviour("tmp_still_seller", buy="naive", sell=still_sell, honest=True, replace=True)
    w = _alone("tmp_still_seller").world
    assert w.tab_valid.any()  # robots found sites: an offer, had it been asked for, would be valid
    assert not w.off_valid.any()  # never asked: the offers are as the world was built


def test_a_seller_whose_rule_draws_is_asked_every_step_neighbours_or_not():
    im.register_behaviour("tmp_still_seller", buy="naive", sell=still_sell, honest=True, replace=True)
    im.register_behaviour("tmp_drawing_seller", buy="naive", sell=drawing_sell, honest=True, replace=True)
    drawing = _alone("tmp_drawing_seller").world
    still = _alone("tmp_still_seller").world
    assert drawing.off_valid.any()  # asked: its offers were written
    # its draws came from the run's generator, so every later draw of the engine moved
    assert not np.array_equal(drawing.pos, still.pos)
