"""A robot without a neighbour is asked for no offer, unless its sell rule draws random numbers, and does not
buy when its buy rule is registered as needing neighbours."""
import numpy as np

import infomarket as im
from infomarket.behaviours.api import install, own_entry
from infomarket.engine.world import FOOD
from infomarket.registry import get_behaviour

from ..conftest import make_config


def still_sell(w, me, site):
    return own_entry(w, me, site)


def drawing_sell(w, me, site, rng):
    rng.random()
    return own_entry(w, me, site)


def marking_buy(w, me, nbrs):
    """Writes its mark into the new table whenever it is called, neighbours or not."""
    install(w, me, FOOD, 123.0, 0.0, 0)


#: The file's behaviours, all compiled into one step kernel (``Simulation``'s ``kernel_kinds``): whether a
#: robot is asked, or called, is decided per kind, so each runs as on a kernel of its own, for one compile.
KINDS = ("tmp_drawing_seller", "tmp_marker", "tmp_quiet_marker", "tmp_still_seller")


def _register() -> None:
    im.register_behaviour("tmp_still_seller", buy="naive", sell=still_sell, honest=True, replace=True)
    im.register_behaviour("tmp_drawing_seller", buy="naive", sell=drawing_sell, honest=True, replace=True)
    im.register_behaviour("tmp_marker", buy=marking_buy, sell=still_sell, honest=True, replace=True)
    im.register_behaviour("tmp_quiet_marker", buy=marking_buy, sell=still_sell, honest=True, replace=True,
                          needs_neighbours=True)


def _simulation(behaviour: str, steps: int, seed: int = 3) -> im.Simulation:
    """Five robots that never communicate (range 0: no robot ever has a neighbour)."""
    _register()
    cfg = make_config(robots=5, behaviour=behaviour, steps=steps, robot={"communication_range": 0.0})
    return im.Simulation(cfg, seed, kernel_kinds=KINDS)


def _alone(behaviour: str, seed: int = 3) -> im.Simulation:
    """Five robots that never communicate, 3 000 steps."""
    sim = _simulation(behaviour, 3000, seed)
    sim.run()
    return sim


def test_a_seller_without_neighbours_is_not_asked_when_asking_draws_nothing():
    w = _alone("tmp_still_seller").world
    assert w.tab_valid.any()  # robots found sites: an offer, had it been asked for, would be valid
    assert not w.off_valid.any()  # never asked: the offers are as the world was built


def test_a_seller_whose_rule_draws_is_asked_every_step_neighbours_or_not():
    drawing = _alone("tmp_drawing_seller").world
    still = _alone("tmp_still_seller").world
    assert drawing.off_valid.any()  # asked: its offers were written
    # its draws came from the run's generator, so every later draw of the engine moved
    assert not np.array_equal(drawing.pos, still.pos)


def test_a_buy_rule_that_needs_neighbours_is_not_called_for_a_robot_without_one():
    for name, called in (("tmp_marker", True), ("tmp_quiet_marker", False)):
        sim = _simulation(name, 10)
        sim.step(1)
        assert (sim.world.new_vec[:, FOOD, 0] == 123.0).all() == called, name
        assert (sim.world.new_vec[:, FOOD, 0] == 123.0).any() == called, name


def test_a_reused_buy_rule_keeps_its_behaviours_setting():
    assert get_behaviour("naive").needs_neighbours
    assert get_behaviour("scaboteur").needs_neighbours  # buy="sceptical"
    assert not get_behaviour("robust_median").needs_neighbours  # it prunes its memory every step
    spec = im.register_behaviour("tmp_reused", buy="robust_median", sell=still_sell, honest=True, replace=True)
    assert not spec.needs_neighbours
    spec = im.register_behaviour("tmp_reused", buy="sceptical", sell=still_sell, honest=True, replace=True)
    assert spec.needs_neighbours
