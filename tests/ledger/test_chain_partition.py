"""``[chain] partition = [start, end]`` (docs/chain-model.md): during steps start <= t < end no chain message
crosses the perpendicular bisector of the first food site (200, 300) and the first nest (1000, 300), the
line x = 600 of the default arena; the market's own contracts are untouched.  Every expected value is
worked out by hand from the rules in docs/chain-model.md (as in ``test_chain.py``): robots are held still
far from both sites, so nobody trades, and the deposits are injected."""
from __future__ import annotations

import numpy as np
import pytest

import infomarket as im
from infomarket.ledger.poa import arena
from infomarket.errors import ConfigError

from .test_chain import R, W0, _branch_deposits, _config, _deposit, _place, _run_conserving_money


def _conserved(w):
    """Every live block's balances add up to the initial wealth plus one reward per deposit on its branch."""
    for b in np.flatnonzero(w.blk_live):
        assert arena.balances_after(w, b).sum() == pytest.approx(4 * W0 + R * _branch_deposits(w, int(b)), abs=1e-12)


def test_a_partitioned_swarm_forks_and_the_lighter_branch_is_undone_when_it_ends():
    """Four robots 10 apart at x = 585, 595 | 605, 615 (range 50: every pair are neighbours), so robots 0, 1
    are on the food's side and 2, 3 on the nest's.  Signers (0, 2), P = 2, delay 3, partition [0, 6).
    Robots 1 and 3 deposit at step 0.

    Nest side: robot 2, in turn for height 1, makes B1 at step 2 (weight 2) with robot 3's deposit (heard at
    step 1).  Food side: robot 0 never hears B1 or robot 3's deposit in the window; out of turn, it makes A1
    at step 5 (weight 1) with robot 1's deposit: a fork, B1 canonical.  At step 6 the partition is over:
    robot 0 hears B1 (heavier) from robots 2 and 3 (a view reorganisation), and in turn for height 2 on B1
    (6 - 2 >= 2) makes B2 (weight 4) with robot 1's deposit again; robot 2 (out of turn: 2 + 5 = 7) does not.
    Every head is then on B1, which becomes final, and A1 is dropped: robot 1's payment undone and redone."""
    sim = im.Simulation(_config(4, period=2, out_of_turn_delay=3, signers=[0, 2], partition=[0, 6]), 1)
    _place(sim, [(585.0, 100.0), (595.0, 100.0), (605.0, 100.0), (615.0, 100.0)])
    w = sim.world
    _deposit(sim, 1)
    _deposit(sim, 3)
    for _ in range(5):
        sim.step(1)
        _conserved(w)
    b1, a1 = int(w.view_head[2]), int(w.view_head[0])
    assert (w.blk_height[b1], w.blk_signer[b1], w.blk_step[b1], w.blk_weight[b1], w.blk_ntx[b1]) == (1, 2, 2, 2, 1)
    assert (w.blk_height[a1], w.blk_signer[a1], w.blk_step[a1], w.blk_weight[a1], w.blk_ntx[a1]) == (1, 0, 5, 1, 1)
    assert int(w.view_head[1]) == 0 and int(w.view_head[3]) == b1  # nothing crossed x = 600
    assert int(w.chn_forks[0]) == 1 and int(w.chn_canon[0]) == b1
    assert arena.balances_after(w, a1).tolist() == [W0, W0 + R, W0, W0]
    assert arena.balances_after(w, b1).tolist() == [W0, W0, W0, W0 + R]
    assert w.balance.tolist() == [W0, W0, W0, W0 + R]
    sim.step(1)
    _conserved(w)
    b2 = int(w.chn_canon[0])
    assert (w.blk_height[b2], w.blk_signer[b2], w.blk_step[b2], w.blk_weight[b2]) == (2, 0, 6, 4)
    assert int(w.blk_parent[b2]) == b1 and not w.blk_live[a1] and int(w.checkpoint[0]) == b1
    assert int(w.chn_view_reorgs[0]) == 1 and int(w.chn_reorgs[0]) == 0
    assert w.balance.tolist() == [W0, W0 + R, W0, W0 + R]  # robot 1's reward, redone on the nest side's chain
    sim.step(1)
    assert set(w.view_head.tolist()) == {b2} and int(w.checkpoint[0]) == b2 and int(w.mp_count[0]) == 0
    assert (int(w.chn_delay_sum[0]), int(w.chn_delay_count[0])) == (2 + 5 + 6, 3)


def test_the_backbone_carries_nothing_across_the_partition():
    """The same signers and deposits, robots far apart (no links at all: (100, 100), (100, 500) | (1100,
    100), (1100, 500)) and a backbone of zero latency, which alone would give every robot B1 at step 2 and
    prevent the fork.  In the window it brings B1 to robot 3 only and A1 (step 5) to robot 1 only.  At step
    6 it brings the rest: robots 0 and 1 take B1 (two view reorganisations), robot 0 makes B2 (in turn,
    weight 4) with robot 1's deposit and the backbone brings it to all at once, so B1 and B2 become final
    in the same step."""
    sim = im.Simulation(_config(4, period=2, out_of_turn_delay=3, signers=[0, 2], backbone=True,
                                partition=[0, 6]), 1)
    _place(sim, [(100.0, 100.0), (100.0, 500.0), (1100.0, 100.0), (1100.0, 500.0)])
    w = sim.world
    _deposit(sim, 1)
    _deposit(sim, 3)
    sim.step(5)
    b1, a1 = int(w.view_head[3]), int(w.view_head[1])
    assert (w.blk_signer[b1], w.blk_step[b1], w.blk_signer[a1], w.blk_step[a1]) == (2, 2, 0, 5)
    assert w.view_head.tolist() == [a1, a1, b1, b1] and int(w.chn_forks[0]) == 1
    assert w.balance.tolist() == [W0, W0, W0, W0 + R]
    _conserved(w)
    sim.step(1)
    b2 = int(w.chn_canon[0])
    assert (w.blk_height[b2], w.blk_signer[b2], w.blk_step[b2], w.blk_weight[b2]) == (2, 0, 6, 4)
    assert w.view_head.tolist() == [b2] * 4 and int(w.checkpoint[0]) == b2 and not w.blk_live[a1]
    assert int(w.chn_view_reorgs[0]) == 2 and int(w.mp_count[0]) == 0
    assert w.balance.tolist() == [W0, W0 + R, W0, W0 + R]


def test_without_the_partition_the_same_swarm_does_not_fork():
    """The first test's swarm with no partition: robot 0 hears robot 3's deposit at step 1 and B1 at step 3
    (before its out-of-turn turn at step 5), so there is no fork and the two deposits are paid by B1 and by
    robot 0's in-turn B2 at step 4 (3 heard B1, in turn for height 2: 2 + 2 = 4)."""
    sim = im.Simulation(_config(4, period=2, out_of_turn_delay=3, signers=[0, 2]), 1)
    _place(sim, [(585.0, 100.0), (595.0, 100.0), (605.0, 100.0), (615.0, 100.0)])
    w = sim.world
    _deposit(sim, 1)
    _deposit(sim, 3)
    sim.step(6)
    assert int(w.chn_forks[0]) == 0 and int(w.chn_view_reorgs[0]) == 0
    assert w.balance.tolist() == [W0, W0 + R, W0, W0 + R]


@pytest.mark.parametrize("window, message", [([5, 5], "chain.partition"), ([7, 3], "chain.partition"),
                                             ([-1, 3], "partition"), ([1, 2, 3], "partition")])
def test_bad_partition_windows_are_refused(window, message):
    with pytest.raises(ConfigError, match=message):
        _config(partition=window)


def test_a_partition_leaves_the_config_hashes_of_chain_setups_without_one_alone():
    cfg = im.load_experiment("fig4C")
    poa = cfg.with_overrides(chain={"consensus": "poa", "period": 5})
    cut = cfg.with_overrides(chain={"consensus": "poa", "period": 5, "partition": [100, 200]})
    assert poa.config_hash() != cut.config_hash()
    assert poa.chain.partition is None and cut.chain.partition == (100, 200)


def test_money_is_conserved_on_every_branch_of_a_partitioned_swarm():
    """A paper-like swarm (25 naive robots, delayed payment, no backbone, P = 5) partitioned during steps
    300-1100: at every step every live block's balances add up to the initial wealth plus one reward per
    deposit on its branch, and the canonical ledger to the initial wealth plus its rewards."""
    from infomarket.config.load import validate

    cfg = validate({"name": "cut", "steps": 1500,
                    "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 25}]},
                    "chain": {"consensus": "poa", "period": 5, "out_of_turn_delay": 2, "partition": [300, 1100]}})
    sim = im.Simulation(cfg, 11)
    _run_conserving_money(sim, 1500)
    m = sim.chain_measures()
    assert m["forks"] > 0 and m["deposits_paid"] > 0
