"""ledger.blocklog: the observer of the chain model's blocks.  Expected blocks come from the rules of
docs/chain-model.md worked by hand (who signs which height at which step), not from the observer."""
from __future__ import annotations

import numpy as np
import pytest

from infomarket import load_experiment
from infomarket.evm.cli import demo_config
from infomarket.engine.simulation import Simulation
from infomarket.errors import SimulationError
from infomarket.ledger.blocklog import BlockLog


def _config(steps, **chain):
    base = demo_config(load_experiment("fig4C"), 25, steps, "staking")
    return base.with_overrides(chain={"consensus": "poa", **chain})


def test_with_a_zero_latency_backbone_block_h_is_made_at_step_3h_by_signer_h_mod_3():
    # period 3, signers [4, 7, 9]: block h is in turn for signers[h % 3], who makes it 3 steps after its
    # parent (the others would wait 3 + 1); the backbone gives it to every robot at once, so there is one
    # chain, every block final in the step it is made (the observer must find each parent itself)
    sim = Simulation(_config(600, period=3, signers=[4, 7, 9], backbone=True), 0)
    log = BlockLog(sim)
    log.run()
    chain = log.canonical()
    assert len(chain) == len(log.blocks) == 201 and log.forks() == []
    for h, blk in enumerate(chain):
        assert (blk.id, blk.height, blk.step) == (h, h, 3 * h)
        assert blk.parent == h - 1
        if h:
            assert blk.signer == [4, 7, 9][h % 3]
    # every transaction sent is in exactly one block: the first one made at or after the step it was sent
    included = [tx for blk in chain for tx in blk.txs]
    assert sorted(tx.seq for tx in included) == sorted(log.txs)
    for blk in chain:
        for tx in blk.txs:
            assert blk.step == 3 * -(-tx.step // 3)
        assert [tx.seq for tx in blk.txs] == sorted(tx.seq for tx in blk.txs)
    assert np.array_equal(chain[-1].balances, sim.world.balance)


def test_gossip_only_forks_and_the_canonical_chain_ends_at_the_ledger():
    sim = Simulation(_config(1500, period=5), 0)
    log = BlockLog(sim)
    log.run()
    chain = log.canonical()
    m = sim.chain_measures()
    assert [b.height for b in chain] == list(range(m["height"] + 1))
    assert all(chain[k].parent == chain[k - 1].id for k in range(1, len(chain)))
    assert all(chain[k].step > chain[k - 1].step for k in range(1, len(chain)))
    assert np.array_equal(chain[-1].balances, sim.world.balance)  # the engine's ledger is the canonical head's
    # blocks made and dropped within one step are not seen; every other one is
    assert 0 < len(log.forks()) <= m["forks"] and len(log.blocks) <= m["blocks"] + 1
    assert set(log.heads()) <= {b.id for b in log.blocks} | {-1}


def test_observing_changes_nothing():
    config = _config(800, period=5, loss=0.2)
    watched = Simulation(config, 3)
    BlockLog(watched).run()
    plain = Simulation(config, 3)
    plain.run()
    assert np.array_equal(watched.world.balance, plain.world.balance)
    assert repr(watched.chain_measures()) == repr(plain.chain_measures())


def test_it_needs_the_chain_and_every_step():
    with pytest.raises(SimulationError, match="chain model"):
        BlockLog(Simulation(demo_config(load_experiment("fig4C"), 25, 10, "staking"), 0))
    sim = Simulation(_config(100, period=5), 0)
    log = BlockLog(sim)
    sim.step(3)
    with pytest.raises(SimulationError, match="one step at a time"):
        log.observe()
