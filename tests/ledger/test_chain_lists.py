"""The chain model's buyers' lists as shared nodes, and the settlement cache (docs/chain-model.md, "Speed").

A buyer's list of open transactions on a branch is a node (``ledger.poa.lists.append_node``): the node of its
last transaction, whose predecessors are the rest.  The same reveal appended to the same list on two
branches is one node, so a node *is* a list's content; a settled list's weights are cached by its node
and reused by any branch that settles the same list.  Expected values are worked by hand from eqs. 7-8
(outlier penalisation, theta = 30 degrees): never read back from the code under test.
"""
from __future__ import annotations

import numpy as np
import pytest
from numba import njit

import infomarket as im
from infomarket.config.load import validate
from infomarket.ledger.poa.lists import append_node, materialise
from infomarket.payments.schemes import outlier_weights


def _config(scheme: str = "outlier", robots: int = 3, **over):
    return validate({
        "name": "chain_lists", "steps": 1000,
        "robot": {"speed": 1e-9},
        "swarm": {"robots": robots, "groups": [{"behaviour": "naive", "count": robots}]},
        "payment": {"scheme": scheme, "stake": 0.04},
        "chain": {"consensus": "poa"},
        **over,
    })


@pytest.fixture(scope="module")
def lists():
    """Buyer 0's lists on two branches that share their first two reveals:
    A = [r1, r2, r3] and B = [r1, r2, r4] (seller, direction in degrees, all at site 0):
    r1 (1, 0), r2 (2, 10), r3 (1, 100), r4 (1, 20).  Nothing steps and no rule runs, so the robots are
    sceptics on the kernel of the forking run below (sceptics and scaboteurs): no kernel of their own."""
    sim = im.Simulation(_config(swarm={"robots": 3, "groups": [{"behaviour": "sceptical", "count": 3}]}), 1,
                        kernel_kinds=("sceptical", "scaboteur"))
    v = sim._view
    n1 = append_node(v, 0, -1, 1, 1, 0, 0.0, 5, 0.04)
    n2 = append_node(v, 0, n1, 2, 2, 0, 10.0, 6, 0.04)
    a = append_node(v, 0, n2, 3, 1, 0, 100.0, 7, 0.04)
    b = append_node(v, 0, n2, 4, 1, 0, 20.0, 8, 0.04)
    return sim, (n1, n2, a, b)


def test_the_same_reveal_on_the_same_list_is_the_same_node(lists):
    sim, (n1, n2, a, b) = lists
    v, w = sim._view, sim.world
    assert len({n1, n2, a, b}) == 4
    assert [int(w.ls_len[x]) for x in (n1, n2, a, b)] == [1, 2, 3, 3]
    assert [int(w.ls_prev[x]) for x in (n1, n2, a, b)] == [-1, n1, n2, n2]
    assert append_node(v, 0, n1, 2, 2, 0, 10.0, 6, 0.04) == n2  # another branch includes r2 on [r1]
    assert append_node(v, 0, -1, 1, 1, 0, 0.0, 5, 0.04) == n1
    top = int(w.ls_top[0])
    # a branch whose seller could lock less, or another buyer's list, is another list
    assert append_node(v, 0, n1, 2, 2, 0, 10.0, 6, 0.03) == top
    assert append_node(v, 1, -1, 1, 1, 0, 0.0, 5, 0.04) == top + 1


def _pool(w, i):
    a, k = int(w.tx_off[i]), int(w.tx_count[i])
    return list(zip(w.tx_seller[a:a + k].tolist(), w.tx_dir[a:a + k].tolist()))


def test_materialise_writes_the_list_of_the_state_into_the_pool(lists):
    """Switching between branches: the pool must hold exactly the list of the state, whether the list it
    held is a beginning of the new one (only the rest is written) or not (all of it is)."""
    sim, (n1, n2, a, b) = lists
    v, w = sim._view, sim.world
    A = [(1, 0.0), (2, 10.0), (1, 100.0)]
    B = [(1, 0.0), (2, 10.0), (1, 20.0)]
    for node, expected in [(a, A), (b, B), (a, A), (n1, A[:1]), (b, B), (-1, []), (n2, A[:2]), (a, A)]:
        w.state_list[0] = node
        materialise(v, 0)
        assert _pool(w, 0) == expected
        assert int(w.pool_list[0]) == node


def test_a_cached_settlement_is_reused_only_for_the_same_list(lists):
    """Settle A, then B, then A again.  Outlier weights: A's directions 0, 10, 100 weigh 2, 2, 1 (0 and 10
    are within 30 degrees of each other, 100 of neither); B's 0, 10, 20 weigh 3, 3, 3.  The sellers share
    0.5 (information share x reward, pot emptied): on A robot 1 gets 0.5 x 3/5 = 0.3 and robot 2 0.2; on B
    robot 1 gets 0.5 x 6/9 = 1/3 and robot 2 1/6.  A's weights reused for B (a stale entry) would pay 0.3."""
    sim, (n1, n2, a, b) = lists
    v, w = sim._view, sim.world
    settle = sim._kernel.settle  # the kernel's settlement, with the chain's cache
    assert w.chn_cache  # outlier penalisation reads only the list

    def pay(node):
        w.state_list[0] = node
        materialise(v, 0)
        w.pot[0] = 0.0
        before = w.balance.copy()
        settle(v, 0, sim.rng)
        w.state_list[0] = w.pool_list[0] = -1  # (what finish_deposit does after a settlement)
        return (w.balance - before).tolist()

    assert int(w.ls_weights_at[a]) == -1 and int(w.ls_weights_at[b]) == -1
    assert pay(a) == pytest.approx([0.5, 0.3, 0.2], abs=1e-12)
    start = int(w.ls_weights_at[a])
    assert start >= 0 and w.weight_store[start:start + 3].tolist() == [2.0, 2.0, 1.0]
    assert pay(b) == pytest.approx([0.5, 1 / 3, 1 / 6], abs=1e-12)
    assert pay(a) == pytest.approx([0.5, 0.3, 0.2], abs=1e-12)  # from the cache
    assert int(w.ls_weights_at[a]) == start


_outlier = njit(outlier_weights)


def outlier_with_rng(buyer, sellers, sites, directions, weights, rng, theta=30.0):
    """The paper's outlier penalisation (``payments.schemes.outlier_weights``) behind a rule that takes
    ``rng`` (and never draws): its weights may not be cached."""
    _outlier(buyer, sellers, sites, directions, weights, theta)


def test_a_forking_run_pays_the_same_with_and_without_the_cache():
    """The reference is the same scheme without the cache (a rule that takes rng is never cached): a
    paper-like swarm with gossip only (many branches settle the same deposits) must give the same
    wealth, reputation and chain measures bit for bit."""
    im.register_payment("tmp_outlier_rng", outlier_with_rng, replace=True)
    over = {"steps": 2500, "swarm": {"robots": 25, "groups": [{"behaviour": "sceptical", "count": 20},
                                                             {"behaviour": "scaboteur", "count": 5}]},
            "robot": {}}
    runs = {}
    for scheme in ("outlier", "tmp_outlier_rng"):
        sim = im.Simulation(_config(scheme, **over).with_overrides(chain={"consensus": "poa", "period": 5}), 3)
        sim.run()
        runs[scheme] = sim
    cached, plain = runs["outlier"], runs["tmp_outlier_rng"]
    assert cached.world.chn_cache and not plain.world.chn_cache
    assert int(cached.world.weight_top[0]) > 0 and int(plain.world.weight_top[0]) == 0
    m = cached.chain_measures()
    assert m["deposits_paid"] > 0 and m["forks"] > 0
    assert m == plain.chain_measures()
    for f in ("balance", "rep_settled", "rep_reduced", "rep_earned", "rep_stake_lost", "gas_paid"):
        assert np.array_equal(getattr(cached.world, f), getattr(plain.world, f)), f
