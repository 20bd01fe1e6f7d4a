"""The defence combinations shipped as experiments (``experiments/defences``): each names a buy rule, a
slashing payment rule with a stake and a Byzantine axis, and runs as it is."""
import numpy as np
import pytest

import infomarket as im
from infomarket.config import load_experiment

COMBINATIONS = {"robust_slash": ("robust_geometric", "consensus_slash"),
                "trust_slash": ("outcome_trust", "outcome_slash")}


@pytest.mark.parametrize("name", sorted(COMBINATIONS))
def test_a_combination_is_one_runnable_experiment(name):
    cfg = load_experiment(name)
    buyer, scheme = COMBINATIONS[name]
    assert cfg.name == name and cfg.swarm.groups[0].behaviour == buyer and cfg.payment.scheme == scheme
    assert cfg.payment.stake > 0 and [a.value for a in cfg.sweep.axes["byzantines"]] == [0, 3]
    res = im.simulate(cfg, seed=0, steps=600)
    wealth = res.robots.wealth.to_numpy()
    assert res.steps == 600 and len(wealth) == 25 and np.isfinite(wealth).all() and (wealth >= -1e-12).all()
