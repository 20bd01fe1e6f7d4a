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
    def random_liar(w, me, site, rng, lie_probability=0.5):
        valid, x, y, age = w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], w.tab_age[me, site]
        if rng.random() < lie_probability:
            return valid, -x, -y, age
        return valid, x, y, age

    spec = im.register_behaviour("tmp_random_liar", buy="naive", sell=random_liar, honest=False, replace=True)
    assert spec.sell.wants_rng and spec.params == ("lie_probability",)
    checks.check_behaviour("tmp_random_liar", steps=800)  # reproducible from the seed, money conserved
