"""``ledger.poa.invariants.check_invariants``: the rules of the chain's four forms of "the ledger after
block b" hold after every step of forking, lossy runs, and each broken form is caught by its rule."""
from __future__ import annotations

import numpy as np
import pytest

import infomarket as im
from infomarket.errors import InternalError
from infomarket.ledger.poa import mempool
from infomarket.ledger.poa.invariants import check_invariants
from infomarket.seeds import run_seed


def _sim(steps: int, **chain) -> im.Simulation:
    """A fig4C swarm on the chain, checked after every step (conftest).  The swarm's own first trades come
    later than these short runs, so every 10 steps one robot sells to another (a reveal) and every 50
    steps each robot that has bought deposits: lists grow and are settled on the branches."""
    cfg = im.load_experiment("fig4C").with_overrides(chain={"consensus": "poa", **chain})
    sim = im.Simulation(cfg, run_seed(cfg.seed, 0))
    n = sim.world.pos.shape[0]
    for k in range(steps // 10):
        sim.step(10)
        buyer, seller = k % n, (7 * k + 3) % n
        if buyer != seller:
            mempool.reveal(sim._view, buyer, seller, k % 2, float(37 * k % 360))
        if k % 5 == 4:
            for i in np.flatnonzero((sim.world.mp_for_buyer > 0) | (sim.world.tx_count > 0)):
                mempool.send_deposit(sim._view, int(i))
    return sim


@pytest.fixture(scope="module")
def forked():
    """Every robot signs, messages are lost, gas is paid: forks, reorganisations, a moving checkpoint."""
    return _sim(400, period=3, out_of_turn_delay=2, loss=0.2, gas_price=1e-7, finality=8)


def test_the_invariants_hold_after_every_step_of_a_forking_run(forked):
    m = forked.chain_measures()
    assert m["forks"] > 0 and m["reorgs"] > 0 and m["deposits_paid"] > 0
    w = forked.world
    assert int(w.blk_height[int(w.checkpoint[0])]) > 0  # the checkpoint moved
    assert int(w.chn_blocks[0]) > int(w.blk_height[int(w.chn_canon[0])])  # branches were made and dropped


def test_the_invariants_hold_with_a_backbone_a_partition_and_signers():
    sim = _sim(300, period=2, backbone=True, latency=3, loss=0.1, signers=[0, 3, 7, 12, 20], partition=[100, 200])
    assert sim.chain_measures()["blocks"] > 0


def _canonical_row(w):
    return int(w.blk_state[int(w.chn_canon[0])])


def _first_list(w):
    """(row, buyer, node) of some buyer's non-empty list in a live state row."""
    for r in np.flatnonzero(w.state_used):
        for i, v in enumerate(w.bs_list[r]):
            if v >= 0:
                return int(r), i, int(v)
    raise AssertionError("no open transaction in any state")


@pytest.mark.parametrize("form, rule", [
    ("live", "the ledger's balance is the canonical row's blk_bal"),
    ("pool", "pool entry"),
    ("rows", "state_used marks exactly the live blocks' rows"),
    ("checkpoint", "ck_pot is the checkpoint's row"),
    ("lists", "counts its nodes"),
    ("views", "view balance is its head's"),
])
def test_each_broken_form_is_caught_by_its_rule(forked, form, rule):
    w = forked.world
    if form == "live":
        target, index = w.balance, (3,)
    elif form == "pool":
        i = int(np.flatnonzero(w.tx_count > 0)[0])
        target, index = w.tx_dir, (int(w.tx_off[i]),)
    elif form == "rows":
        target, index = w.state_used, (int(np.flatnonzero(~w.state_used)[0]),)
    elif form == "checkpoint":
        target, index = w.ck_pot, (0,)
    elif form == "lists":
        _, _, v = _first_list(w)
        target, index = w.ls_len, (v,)
    else:
        i = int(np.flatnonzero(w.view_head >= 0)[0])
        target, index = w.view_bal, (i,)
    check_invariants(w)
    old = target[index]
    target[index] = (not old) if target.dtype == np.bool_ else old + 1
    try:
        with pytest.raises(InternalError, match=rule):
            check_invariants(w)
    finally:
        target[index] = old
    check_invariants(w)
