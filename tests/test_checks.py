"""Every registered rule passes the public checkers; the checkers catch broken rules."""
import numpy as np
import pytest

import infomarket as im
from infomarket import checks
from infomarket.engine.simulation import Simulation
from infomarket.registry import behaviours, payments

from .shared_kernel import BUILTIN, shared_kinds


@pytest.mark.parametrize("name", sorted(behaviours()))
def test_every_registered_behaviour_passes(name):
    # every built-in behaviour compiled into each check's kernel: one kernel per scheme (two more for
    # waypoint paths) instead of two per behaviour, shared with the tests that run behaviour mixes
    checks.check_behaviour(name, steps=1500, alongside=BUILTIN)


def test_a_run_on_a_shared_kernel_is_the_run_on_its_own():
    # saboteur is not first among the shared kinds: a robot's kind must index the kernel's kinds
    cfg = checks._swarm("saboteur", 10, "delayed", 0.0, 600)
    own = Simulation(cfg, 3, record_events=True)
    shared = Simulation(cfg, 3, record_events=True, kernel_kinds=shared_kinds(cfg))
    assert shared.kinds == checks._kernel_kinds("saboteur", BUILTIN)  # the rule checks' kernel
    assert shared.kinds.index("saboteur") != own.kinds.index("saboteur")
    assert shared.kernel_source != own.kernel_source
    a, b = own.run(), shared.run()
    assert len(a.events) > 50 and (a.events.kind == "purchase").any()
    assert a.robots.equals(b.robots) and a.events.equals(b.events) and a.payments.equals(b.payments)


def test_check_behaviours_names_a_rule_that_keeps_the_shared_kernel_from_compiling():
    def three_values(w, me, site):
        return True, 1.0, 0.0

    im.register_behaviour("tmp_three_values", buy="naive", sell=three_values, honest=False, replace=True)
    # naive is checked first, on the kernel of both: its own rules compile, so only checking each alone
    # names the rule at fault
    with pytest.raises(im.errors.RuleRunError, match="'tmp_three_values': its sell rule three_values .* returns"):
        checks.check_behaviours(["naive", "tmp_three_values"], steps=300)


def test_kernel_kinds_must_hold_the_experiments_behaviours_and_its_step():
    cfg = checks._swarm("saboteur", 10, "delayed", 0.0, 600)
    with pytest.raises(im.errors.ArgumentError, match="missing \\['saboteur'\\]"):
        Simulation(cfg, 3, kernel_kinds=("naive", "greedy"))
    with pytest.raises(im.errors.ArgumentError, match="waypoint paths"):
        Simulation(cfg, 3, kernel_kinds=("naive", "saboteur", "waypoint"))
    assert checks._kernel_kinds("saboteur", ["waypoint", "greedy", "naive"]) == ("naive", "greedy", "saboteur")
    assert checks._kernel_kinds("waypoint", ["waypoint", "greedy", "naive"]) == ("naive", "waypoint")


@pytest.mark.parametrize("name", sorted(payments()))
def test_every_registered_payment_scheme_passes(name):
    checks.check_payment(name, sequences=10)


def test_a_scheme_with_negative_weights_is_caught():
    def bad(buyer, sellers, sites, directions, weights):
        for x in range(weights.shape[0]):
            weights[x] = -1.0

    im.register_payment("tmp_negative", bad, replace=True)
    with pytest.raises(im.SimulationError, match="negative"):
        checks.check_payment("tmp_negative", sequences=3)


def noisy_sell(w, me, site):
    return True, np.random.random() * 100.0, 0.0, 0  # numba's own global RNG: not seeded per run


def random_age_liar(w, me, site, rng, spread=3.0):
    """Sells its entry claiming an age of 1, 2 or 3, drawn at random."""
    return w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], 1 + int(rng.random() * spread)


def past_the_table(w, me, site):
    n = w.tab_valid.shape[0]
    return w.tab_valid[n + 3, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], 0


#: The sell rules above, which the checkers must catch (or pass), compiled into one step kernel per scheme
#: (``check_behaviour``'s ``alongside``) rather than one per rule: a robot calls only its own rules.
CAUGHT = ("tmp_noisy", "tmp_past_the_table", "tmp_random_liar")


def _register_caught():
    im.register_behaviour("tmp_noisy", buy="naive", sell=noisy_sell, honest=False, replace=True)
    im.register_behaviour("tmp_past_the_table", buy="naive", sell=past_the_table, honest=False, replace=True)
    return im.register_behaviour("tmp_random_liar", buy="naive", sell=random_age_liar, honest=False, replace=True)


def test_a_nondeterministic_seller_is_caught():
    _register_caught()
    with pytest.raises(checks.CheckFailed, match="same seed"):
        checks.check_behaviour("tmp_noisy", steps=300, alongside=CAUGHT)


def test_a_random_rule_gets_the_runs_generator_and_stays_reproducible():
    spec = _register_caught()
    assert spec.sell.wants_rng and spec.params == ("spread",)
    checks.check_behaviour("tmp_random_liar", steps=800, alongside=CAUGHT)  # reproducible, money conserved

    cfg = im.Experiment.model_validate({"steps": 1500, "swarm": {"robots": 25, "groups": [
        {"behaviour": "naive", "count": 20}, {"behaviour": "tmp_random_liar", "count": 5}]}})

    def liar_sales(seed):
        ev = Simulation(cfg, seed, record_events=True, kernel_kinds=("naive", *CAUGHT)).run().events
        return ev[(ev.kind == "purchase") & (ev.seller >= 20)].age.to_numpy()

    ages = liar_sales(1)
    # the rule really draws: a constant generator would give one claimed age, this one gives all three
    counts = np.bincount(ages, minlength=4)[1:]
    assert len(ages) >= 60 and counts.min() >= len(ages) / 50, counts
    assert np.array_equal(liar_sales(1), ages)  # from the run's seeded generator
    assert not np.array_equal(liar_sales(2), ages)


def test_a_payment_rule_writing_out_of_bounds_is_caught_with_its_file_and_line():
    # issue 21: compiled without bounds checking this wrote past `weights` and passed
    def past_the_end(buyer, sellers, sites, directions, weights):
        for x in range(weights.shape[0]):
            weights[x] = 1.0
        weights[weights.shape[0] + 5] = 1.0

    im.register_payment("tmp_past_the_end", past_the_end, replace=True)
    line = past_the_end.__code__.co_firstlineno + 3
    with pytest.raises(checks.CheckFailed) as err:
        checks.check_payment("tmp_past_the_end", sequences=3)
    msg = str(err.value)
    assert "'tmp_past_the_end'" in msg and "past_the_end" in msg and "out of bounds" in msg
    assert f"{__file__}:{line}" in msg


def test_a_sell_rule_without_its_site_argument_is_refused_at_registration():
    def no_site(w, me, rotation=90.0):  # issue 21: registered, ran and passed check_behaviour
        return True, 1.0, 0.0, 0

    with pytest.raises(im.errors.RuleError) as err:
        im.register_behaviour("tmp_no_site", buy="naive", sell=no_site, honest=False, replace=True)
    msg = str(err.value)
    assert "sell rule no_site" in msg and "w, me, site first" in msg and "'rotation', not 'site'" in msg
    assert f"{__file__}:{no_site.__code__.co_firstlineno}" in msg
    assert "tmp_no_site" not in im.registry.behaviours()

    def bad_buy(w, me, neighbours):
        pass

    with pytest.raises(im.errors.RuleError, match="'neighbours', not 'nbrs'"):
        im.register_behaviour("tmp_bad_buy", buy=bad_buy, sell="naive", honest=True, replace=True)

    def bad_pay(buyer, sellers, sites, weights):
        pass

    with pytest.raises(im.errors.RuleError, match="payment rule bad_pay"):
        im.register_payment("tmp_bad_pay", bad_pay, replace=True)


def test_the_decorators_take_limits_as_the_docs_say():
    @im.payment("tmp_limited", limits={"share": ("in [0, 1]", lambda v: 0 <= v <= 1)})
    def limited(buyer, sellers, sites, directions, weights, share=0.5):
        for x in range(weights.shape[0]):
            weights[x] = share

    @im.behaviour("tmp_limited_liar", buy="naive", honest=False, limits={"age": (">= 0", lambda v: v >= 0)})
    def limited_sell(w, me, site, age=1.0):
        return w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], int(age)

    assert im.registry.payments()["tmp_limited"].check("share", 2.0) == "must be in [0, 1]"
    assert im.registry.behaviours()["tmp_limited_liar"].check("age", -1.0) == "must be >= 0"
    assert im.registry.behaviours()["tmp_limited_liar"].check("age", 3.0) is None


def test_a_sell_rule_reading_out_of_bounds_is_caught_with_its_file_and_line():
    # compiled without bounds checking this read past `tab_valid` and passed check_behaviour
    _register_caught()
    with pytest.raises(checks.CheckFailed) as err:
        checks.check_behaviour("tmp_past_the_table", steps=300, alongside=CAUGHT)
    msg = str(err.value)
    assert "behaviour 'tmp_past_the_table': its sell rule past_the_table indexes an array out of bounds" in msg
    assert f"{__file__}:{past_the_table.__code__.co_firstlineno + 2}" in msg
