"""Every registered rule passes the public checkers; the checkers catch broken rules."""
import numpy as np
import pytest

import infomarket as im
from infomarket import checks
from infomarket.registry import behaviours, payments


@pytest.mark.parametrize("name", sorted(behaviours()))
def test_every_registered_behaviour_passes(name):
    checks.check_behaviour(name, steps=1500)


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


def test_a_nondeterministic_seller_is_caught():
    def noisy_sell(w, me, site):
        return True, np.random.random() * 100.0, 0.0, 0  # numba's own global RNG: not seeded per run

    im.register_behaviour("tmp_noisy", buy="naive", sell=noisy_sell, honest=False, replace=True)
    with pytest.raises(checks.CheckFailed, match="same seed"):
        checks.check_behaviour("tmp_noisy", steps=300)


def test_a_random_rule_gets_the_runs_generator_and_stays_reproducible():
    def random_age_liar(w, me, site, rng, spread=3.0):
        """Sells its entry claiming an age of 1, 2 or 3, drawn at random."""
        return w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], 1 + int(rng.random() * spread)

    spec = im.register_behaviour("tmp_random_liar", buy="naive", sell=random_age_liar, honest=False, replace=True)
    assert spec.sell.wants_rng and spec.params == ("spread",)
    checks.check_behaviour("tmp_random_liar", steps=800)  # reproducible from the seed, money conserved

    cfg = im.Experiment.model_validate({"steps": 1500, "swarm": {"robots": 25, "groups": [
        {"behaviour": "naive", "count": 20}, {"behaviour": "tmp_random_liar", "count": 5}]}})

    def liar_sales(seed):
        ev = im.simulate(cfg, seed=seed, record_events=True).events
        return ev[(ev.kind == "purchase") & (ev.seller >= 20)].age.to_numpy()

    ages = liar_sales(1)
    # the rule really draws: a constant generator would give one claimed age, this one gives all three
    counts = np.bincount(ages, minlength=4)[1:]
    assert len(ages) >= 60 and counts.min() >= len(ages) / 50, counts
    assert np.array_equal(liar_sales(1), ages)  # from the run's seeded generator
    assert not np.array_equal(liar_sales(2), ages)
