"""The chain model (docs/chain-model.md): robots as blockchain nodes.

Every expected value below is worked out by hand from the rules in docs/chain-model.md (who signs which
height when, how far news travels per step, which branch is heavier, what gas costs), never read back
from the code under test.  Robots are held still (a speed of 1e-9, far from both sites, so nobody
trades) and transactions are injected where a test needs them, so the story of each test is exactly the
one its comments tell.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import infomarket as im
from infomarket.config.load import validate
from infomarket.errors import ConfigError
from infomarket.ledger.poa import arena, blocks, mempool

W0 = 1.0  # initial wealth
R = 1.0  # reward


def _config(robots: int = 4, *, comm: float = 50.0, speed: float = 1e-9, scheme: str = "delayed",
            stake: float = 0.0, **chain):
    return validate({
        "name": "chain_test", "steps": 1000,
        "robot": {"speed": speed, "communication_range": comm},
        "swarm": {"robots": robots, "groups": [{"behaviour": "naive", "count": robots}]},
        "payment": {"scheme": scheme, "stake": stake},
        "chain": {"consensus": "poa", **chain},
    })


def _place(sim, points):
    """Put the robots at these points (far from both sites: nobody senses one, so nobody trades)."""
    sim.world.pos[:] = np.array(points, dtype=np.float64)


def _deposit(sim, robot):
    """Robot ``robot`` sends a deposit transaction now (as if it had just dropped an item)."""
    mempool.send_deposit(sim._view, robot)


def _canonical(sim):
    w = sim.world
    c = int(w.chn_canon[0])
    return int(w.blk_height[c]), int(w.blk_signer[c]), int(w.blk_step[c])


# ---- configuration ---------------------------------------------------------------------------------------

def test_the_chain_is_off_by_default_and_leaves_the_paper_hashes_alone():
    """The hashes of fig4C and fig2A as the code before the chain model computed them."""
    cfg = im.load_experiment("fig4C")
    assert not cfg.chain.enabled
    assert cfg.config_hash() == "6d59b4a883247a60"
    assert im.load_experiment("fig2A").config_hash() == "93b0d0974ae24300"
    on = cfg.model_copy(update={"chain": cfg.chain.model_copy(update={"consensus": "poa"})})
    assert on.config_hash() != cfg.config_hash()


@pytest.mark.parametrize("chain, message", [
    ({"signers": [7]}, "robot 7 does not exist"),
    ({"signers": [1, 1]}, "listed twice"),
    ({"loss": 1.0}, "loss"),
    ({"period": 0}, "period"),
])
def test_bad_chain_sections_are_refused_with_the_key(chain, message):
    with pytest.raises(ConfigError, match=message):
        _config(**chain)


@pytest.mark.parametrize("payment", [{"stake_expiry": 10}, {"reputation_decay": 0.9}])
def test_fuel_stake_expiry_and_reputation_decay_are_refused_with_the_chain(payment):
    with pytest.raises(ConfigError, match=r"fuel_cost, payment\.stake_expiry or payment\.reputation_decay"):
        validate({"swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2}]},
                  "payment": payment, "chain": {"consensus": "poa"}})


# ---- blocks ----------------------------------------------------------------------------------------------

def test_a_block_every_period_by_the_in_turn_signer():
    """P = 3, signers (2, 5, 7), a backbone of zero latency: everyone always has the newest block, so
    block h is made at step 3h by signers[h % 3]: 5 at step 3, 7 at 6, 2 at 9, 5 at 12."""
    sim = im.Simulation(_config(8, period=3, signers=[2, 5, 7], backbone=True), 1)
    seen = []
    for _ in range(12):
        sim.step(1)
        seen.append(_canonical(sim))
    made = [s for k, s in enumerate(seen) if k == 0 or s != seen[k - 1]]
    assert made == [(0, -1, 0), (1, 5, 3), (2, 7, 6), (3, 2, 9), (4, 5, 12)]
    assert [s[0] for s in seen] == [0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4]
    assert int(sim.world.chn_blocks[0]) == 4 and int(sim.world.chn_forks[0]) == 0
    assert set(sim.world.view_head.tolist()) == {int(sim.world.chn_canon[0])}


def test_an_out_of_turn_signer_waits_the_delay_and_weighs_less():
    """No links at all (communication range 0), signers (0, 1), P = 2, delay 1: robot 1 is in turn for
    height 1 and signs at step 2 (weight 2); robot 0, out of turn, signs its own height 1 at step 2 + 1
    = 3 (weight 1): a fork, and robot 1's block stays canonical.  At step 5 robot 0 (in turn for height 2
    on its block of step 3) and robot 1 (out of turn on its block of step 2: 2 + 3) both sign."""
    sim = im.Simulation(_config(2, comm=0.0, period=2, out_of_turn_delay=1, signers=[0, 1]), 1)
    w = sim.world
    sim.step(2)
    h1 = int(w.view_head[1])
    assert (w.blk_height[h1], w.blk_signer[h1], w.blk_step[h1], w.blk_weight[h1]) == (1, 1, 2, 2)
    assert int(w.view_head[0]) == 0  # robot 0 still on genesis
    sim.step(1)
    h0 = int(w.view_head[0])
    assert (w.blk_height[h0], w.blk_signer[h0], w.blk_step[h0], w.blk_weight[h0]) == (1, 0, 3, 1)
    assert int(w.chn_forks[0]) == 1 and int(w.chn_canon[0]) == h1
    sim.step(1)
    assert int(w.chn_blocks[0]) == 2
    sim.step(1)
    a, b = int(w.view_head[0]), int(w.view_head[1])
    assert (w.blk_step[a], w.blk_weight[a], w.blk_step[b], w.blk_weight[b]) == (5, 3, 5, 3)
    assert int(w.chn_canon[0]) == (a if w.blk_hash[a] < w.blk_hash[b] else b)  # a tie: the lower hash


# ---- gossip ----------------------------------------------------------------------------------------------

def test_a_transaction_reaches_a_robot_k_hops_away_after_k_steps():
    """Six robots in a line 40 apart (range 50: each hears only the next): a deposit robot 0 sends at
    step 0 is known to robots 0..k after k gossip rounds.  No block is due (P = 1000)."""
    sim = im.Simulation(_config(6, period=1000), 1)
    _place(sim, [(100.0 + 40.0 * i, 100.0) for i in range(6)])
    _deposit(sim, 0)
    w = sim.world
    tx = int(np.flatnonzero(w.mp_live)[0])

    def knowers():
        return [i for i in range(6) if (int(w.mp_known[i, tx >> 6]) >> (tx & 63)) & 1]

    assert knowers() == [0]
    for k in range(1, 7):
        sim.step(1)
        assert knowers() == list(range(min(k, 5) + 1)), k


def test_a_block_spreads_one_hop_per_step_and_views_lag_meanwhile():
    """The same line, P = 5, only robot 5 signs: its first block (height 1, step 5) reaches robot 5 - k at
    step 5 + k."""
    sim = im.Simulation(_config(6, period=5, signers=[5]), 1)
    _place(sim, [(100.0 + 40.0 * i, 100.0) for i in range(6)])
    w = sim.world
    sim.step(5)
    heights = []
    for _ in range(5):
        heights.append([int(w.blk_height[h]) for h in w.view_head])
        sim.step(1)
    assert heights == [[0, 0, 0, 0, 0, 1], [0, 0, 0, 0, 1, 1], [0, 0, 0, 1, 1, 1], [0, 0, 1, 1, 1, 1],
                       [0, 1, 1, 1, 1, 1]]
    # lag is counted at each step's gossip: the canonical height is 1 from step 6's on, and robot k
    # reaches it at step 10 - k, so through step 10 robot k lagged one block at steps 6 .. 9 - k
    assert w.chn_lag_sum.tolist() == [4, 3, 2, 1, 0, 0]


def test_lost_messages_follow_the_loss_probability():
    """Two neighbours, loss 0.3: a message gets through in about 70 % of 4 000 rounds (binomial sd 0.7 %)."""
    sim = im.Simulation(_config(2, period=100000, loss=0.3), 5)
    _place(sim, [(100.0, 100.0), (130.0, 100.0)])
    w = sim.world
    got = 0
    for _ in range(4000):
        _deposit(sim, 0)
        tx = int(np.flatnonzero(w.mp_live)[0])
        sim.step(1)
        got += (int(w.mp_known[1, tx >> 6]) >> (tx & 63)) & 1
        sim.world.mp_live[:] = False  # (test only) empty the mempool again (its sending order too)
        sim.world.mp_count[0] = 0
        sim.world.mp_known[:] = 0
    assert abs(got / 4000 - 0.7) < 0.035


# ---- forks and reorganisations -----------------------------------------------------------------------------

def test_a_partition_forks_and_its_payments_are_redone_when_it_reconnects():
    """Side A = robots 0, 1 at (100, 100); side B = robots 2, 3 at (1000, 500); signers (0, 2); P = 2,
    delay 3 (out of turn: 5 steps).  Robot 1 and robot 3 each deposit at step 0.

    B: robot 2 is in turn for height 1: B1 at step 2 (weight 2) with robot 3's deposit (heard at step 1).
    A: robot 0 is out of turn: A1 at step 5 (weight 1) with robot 1's deposit: a fork.  B1 is heavier:
    canonical, so robot 1's reward is paid on A's chain only.  Reconnected after step 5, robot 0 hears B1
    at step 6 (its head moves to another branch: a view reorganisation), A1 dies, and robot 0, in turn
    for height 2 on B1 (2 + 2 <= 6), makes B2 at step 6 (weight 4) with robot 1's deposit again."""
    sim = im.Simulation(_config(4, period=2, out_of_turn_delay=3, signers=[0, 2]), 1)
    A = [(100.0, 100.0), (130.0, 100.0)]
    _place(sim, A + [(1000.0, 500.0), (1030.0, 500.0)])
    w = sim.world
    _deposit(sim, 1)
    _deposit(sim, 3)
    sim.step(2)
    b1 = int(w.view_head[2])
    assert (w.blk_height[b1], w.blk_weight[b1], w.blk_ntx[b1]) == (1, 2, 1)
    assert arena.balances_after(w, b1).tolist() == [W0, W0, W0, W0 + R]
    sim.step(3)
    a1 = int(w.view_head[0])
    assert (w.blk_height[a1], w.blk_weight[a1], w.blk_step[a1], w.blk_ntx[a1]) == (1, 1, 5, 1)
    assert arena.balances_after(w, a1).tolist() == [W0, W0 + R, W0, W0]
    assert int(w.chn_forks[0]) == 1 and int(w.chn_canon[0]) == b1
    assert w.balance.tolist() == [W0, W0, W0, W0 + R]  # the canonical ledger: B's chain
    assert int(w.view_head[1]) == 0 and int(w.view_head[3]) == b1  # robot 1 hears of A1 at step 6 only
    assert int(w.mp_count[0]) == 2  # neither deposit is in a block every robot's head descends from
    # reconnect
    _place(sim, [(1000.0, 520.0), (1010.0, 540.0), (1000.0, 500.0), (1030.0, 500.0)])
    sim.step(1)
    b2 = int(w.chn_canon[0])
    assert (w.blk_height[b2], w.blk_signer[b2], w.blk_step[b2], w.blk_weight[b2]) == (2, 0, 6, 4)
    assert w.blk_parent[b2] == b1 and not w.blk_live[a1]
    assert int(w.chn_view_reorgs[0]) == 1 and int(w.chn_reorgs[0]) == 0
    assert w.balance.tolist() == [W0, W0 + R, W0, W0 + R]  # robot 1's reward, redone on B's chain
    sim.step(1)
    assert set(w.view_head.tolist()) == {b2} and int(w.checkpoint[0]) == b2 and int(w.mp_count[0]) == 0
    # deposit-to-payment delays of each paying block: B1 2 - 0, A1 5 - 0, B2 6 - 0
    assert (int(w.chn_delay_sum[0]), int(w.chn_delay_count[0])) == (13, 3)


def test_a_heavier_branch_takes_over_the_canonical_chain_and_its_transactions_are_counted():
    """Two robots with no links, signers (0, 1), P = 2, delay 1; each deposits at step 0.  Robot 1 (in
    turn for height 1) makes X1 at step 2 (weight 2, its deposit); robot 0 makes Z1 at step 3 (weight
    1, its deposit).  At step 5 robot 0, in turn for height 2, makes Z2 (weight 3): heavier than X1 and
    not on X1's branch, so the canonical head moves: one reorganisation, taking X1's deposit out.  Then
    robot 1, out of turn, makes X2 (weight 3 too): a tie, which the lower hash decides; if X2 wins, that
    is a second reorganisation, taking Z1's deposit out."""
    sim = im.Simulation(_config(2, comm=0.0, period=2, out_of_turn_delay=1, signers=[0, 1]), 1)
    w = sim.world
    _deposit(sim, 0)
    _deposit(sim, 1)
    sim.step(4)
    x1 = int(w.chn_canon[0])
    assert (w.blk_signer[x1], w.blk_weight[x1]) == (1, 2) and w.balance.tolist() == [W0, W0 + R]
    assert int(w.chn_reorgs[0]) == 0
    sim.step(1)
    z2, x2 = int(w.view_head[0]), int(w.view_head[1])
    assert (w.blk_weight[z2], w.blk_weight[x2], w.blk_step[z2], w.blk_step[x2]) == (3, 3, 5, 5)
    x_wins = bool(w.blk_hash[x2] < w.blk_hash[z2])
    assert int(w.chn_canon[0]) == (x2 if x_wins else z2)
    assert int(w.chn_reorgs[0]) == 1 + x_wins
    assert int(w.chn_reorg_tx[0]) == 1 + x_wins
    assert w.balance.tolist() == ([W0, W0 + R] if x_wins else [W0 + R, W0])
    assert arena.balances_after(w, z2).tolist() == [W0 + R, W0] and arena.balances_after(w, x2).tolist() == [W0, W0 + R]


def test_a_robot_left_behind_past_the_finality_depth_keeps_its_view_until_it_hears_a_heavier_block():
    """Finality 2, two robots 300 apart, only robot 1 signs, P = 1: X1, X2, X3 at steps 1, 2, 3.  At step 3
    X1 is 2 blocks below the head: final, although robot 0 is still on genesis.  Genesis is dropped and
    robot 0 keeps what it knew (height 0, its balance) with no head block; its lag grows by the canonical
    height each step (1 + 2 at steps 2 and 3, 3 + 4 at 4 and 5).  Moved next to robot 1 after step 5,
    it takes X5 at step 6's gossip: a view reorganisation (its branch was dropped)."""
    sim = im.Simulation(_config(2, period=1, signers=[1], finality=2), 1)
    _place(sim, [(100.0, 100.0), (400.0, 100.0)])
    w = sim.world
    _deposit(sim, 0)
    sim.step(2)
    assert int(w.blk_height[w.checkpoint[0]]) == 0 and int(w.view_head[0]) == 0
    sim.step(1)
    assert int(w.blk_height[w.checkpoint[0]]) == 1 and int(w.view_head[0]) == -1
    assert (int(w.view_height[0]), w.view_bal[0]) == (0, W0)
    assert int(w.mp_count[0]) == 1  # robot 0's deposit: nobody else knows it
    sim.step(2)
    assert w.chn_lag_sum.tolist() == [1 + 2 + 3 + 4, 0] and int(w.chn_view_reorgs[0]) == 0
    _place(sim, [(100.0, 100.0), (130.0, 100.0)])
    sim.step(1)
    assert int(w.view_height[0]) == 5 and int(w.chn_view_reorgs[0]) == 1
    sim.step(1)  # robot 1 heard robot 0's deposit at step 6's gossip too: X6 holds it
    assert w.balance.tolist() == [W0 + R, W0]


def _branch_deposits(w, b, known=None):
    """Deposits on block b's branch: those settled by the checkpoint, plus the deposit transactions in
    the blocks from the checkpoint to b.  ``known``: the counts of blocks found so far in this state of
    the world (a dict this fills in), so a walk stops at the first block whose branch is counted."""
    known = {} if known is None else known
    ck = int(w.checkpoint[0])
    path = []
    while b != ck and b not in known:
        path.append(b)
        b = int(w.blk_parent[b])
    count = known[b] if b != ck else int(w.ck_rep_deposits.sum())
    for b in reversed(path):
        off = int(w.blk_txoff[b])
        count += int((w.mp_kind[w.blk_tx[off:off + int(w.blk_ntx[b])]] == mempool.DEPOSIT).sum())
        known[b] = count
    return count


def test_blocks_without_transactions_share_a_state_that_outlives_the_block_that_made_it():
    """Robot 1 the only signer, P = 1, finality depth 1, no links and no backbone: robot 0 never hears a
    block, so a block is final once one block lies on it.  Step 1: robot 1 sells robot 0 a vector and
    deposits an item: block 1 includes both (balances 1 and 1 + 1; robot 0's open list holds the sale).
    Steps 2 and 3 bring no transaction: blocks 2 and 3 include none, and the state after each is block 1's
    (one state for the three).  After step 3 block 1 is dropped (block 2 is the checkpoint) and its state
    lives on for blocks 2 and 3.  Step 4: robot 1 deposits again: block 4 has a state of its own (1, 3)."""
    sim = im.Simulation(_config(2, comm=0.0, period=1, signers=[1], finality=1), 1)
    w = sim.world
    assert bool(mempool.reveal(sim._view, 0, 1, 0, 45.0))
    _deposit(sim, 1)
    sim.step(1)
    b1 = int(w.view_head[1])
    assert w.blk_ntx[b1] == 2 and w.balance.tolist() == [W0, W0 + R]
    assert w.tx_seller[w.tx_off[0]:w.tx_off[0] + w.tx_count[0]].tolist() == [1]  # the pool holds the sale
    sim.step(1)
    b2 = int(w.view_head[1])
    assert w.blk_ntx[b2] == 0 and w.blk_state[b2] == w.blk_state[b1] and int(w.checkpoint[0]) == b1
    sim.step(1)
    b3 = int(w.view_head[1])
    assert int(w.checkpoint[0]) == b2 and not w.blk_live[b1] and w.blk_live[b3]
    assert w.blk_state[b3] == w.blk_state[b1]
    for b in (b2, b3):
        assert arena.balances_after(w, b).tolist() == [W0, W0 + R]
    assert w.blk_live[w.state_block[0]]  # the ledger arrays hold the state of a live block
    assert w.balance.tolist() == [W0, W0 + R] and w.tx_count.tolist() == [1, 0]
    _deposit(sim, 1)
    sim.step(1)
    b4 = int(w.view_head[1])
    assert w.blk_state[b4] != w.blk_state[b3] and int(w.checkpoint[0]) == b3
    assert arena.balances_after(w, b4).tolist() == [W0, W0 + 2 * R]
    assert arena.balances_after(w, b3).tolist() == [W0, W0 + R]
    assert w.balance.tolist() == [W0, W0 + 2 * R]


def _list_sellers(w, v):
    """The sellers of the list that ends with node v, oldest first (walked through ``ls_prev``)."""
    out = []
    while v >= 0:
        out.append(int(w.ls_seller[v]))
        v = int(w.ls_prev[v])
    return out[::-1]


def _run_conserving_money(sim, steps, robots=25):
    """Step ``sim`` one step at a time; after each, every live block's balances add up to the initial
    wealth plus one reward per deposit on its branch, and the canonical ledger to the initial wealth plus
    its rewards.  And the ledger arrays are the canonical head's state: its balances, every buyer's list in
    the pool (what a rule or the results read), held for a live block with the head's state."""
    for _ in range(steps):
        sim.step(1)
        w = sim.world
        known: dict = {}
        for b in np.flatnonzero(w.blk_live):
            assert arena.balances_after(w, b).sum() == pytest.approx(
                robots * W0 + R * _branch_deposits(w, int(b), known), abs=1e-9)
        assert w.balance.sum() + w.pot.sum() == pytest.approx(robots * W0 + R * int(w.rep_deposits.sum()), abs=1e-9)
        canon, cur = int(w.chn_canon[0]), int(w.state_block[0])
        assert w.blk_live[cur] and w.blk_state[cur] == w.blk_state[canon]
        assert np.array_equal(w.balance, arena.balances_after(w, canon))
        for i in range(robots):
            pool = w.tx_seller[w.tx_off[i]:w.tx_off[i] + w.tx_count[i]].tolist()
            assert pool == _list_sellers(w, int(w.bs_list[w.blk_state[canon], i]))


def test_money_is_conserved_on_every_branch_of_a_forking_swarm():
    """A paper-like swarm (25 naive robots, delayed payment, no backbone, range 50 in 1200 x 600: the
    communication graph is split most of the time), P = 5: forks and reorganisations happen on their
    own.  At every step every live block's balances add up to the initial wealth plus one reward per
    deposit on its branch, and the canonical ledger to the initial wealth plus its rewards."""
    cfg = validate({"name": "forks", "steps": 1500,
                       "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 25}]},
                       "chain": {"consensus": "poa", "period": 5, "out_of_turn_delay": 2}})
    sim = im.Simulation(cfg, 11)
    _run_conserving_money(sim, 1500)
    m = sim.chain_measures()
    assert m["forks"] > 0 and m["view_reorgs"] > 0 and m["deposits_paid"] > 0


# ---- gas -------------------------------------------------------------------------------------------------

def test_gas_is_charged_exactly():
    """Gas price 1e-7, delayed payment, backbone, P = 1.  Robot 0 sells to robot 1 (a reveal: 115 335 gas,
    docs/gas.md), then robot 1 deposits (settling 1 reveal: 155 967 gas).  Seller: 1 - 0.0115335 + 0.5;
    buyer: 1 + 1 - 0.5 - 0.0155967."""
    sim = im.Simulation(_config(2, period=1, backbone=True, gas_price=1e-7), 1)
    _place(sim, [(100.0, 100.0), (130.0, 100.0)])
    w = sim.world
    assert bool(mempool.reveal(sim._view, 1, 0, 0, 45.0))
    assert w.view_avail[0] == pytest.approx(1.0 - 0.0115335, abs=1e-15)
    sim.step(1)
    assert w.balance.tolist() == pytest.approx([1.0 - 0.0115335, 1.0], abs=1e-15)
    _deposit(sim, 1)
    sim.step(1)
    assert w.balance.tolist() == pytest.approx([1.0 - 0.0115335 + 0.5, 1.0 + 1.0 - 0.5 - 0.0155967], abs=1e-12)
    assert w.gas_paid.tolist() == pytest.approx([0.0115335, 0.0155967], abs=1e-15)


def test_a_seller_whose_view_cannot_pay_the_gas_is_refused():
    """Gas price 5e-6: a reveal costs 0.576675 (115 335 gas), so a seller holding 1 can sign one light
    contract but not a second before a block confirms anything."""
    sim = im.Simulation(_config(2, period=1000, gas_price=5e-6), 1)
    assert bool(mempool.reveal(sim._view, 1, 0, 0, 45.0))
    assert not bool(mempool.reveal(sim._view, 1, 0, 0, 45.0))


def test_the_deposit_gas_table_interpolates_the_measured_points():
    """Delayed payment (docs/gas.md): between the measured n = 4 (181 808) and n = 16 (285 219), n = 10 is
    halfway, 233 513.5; n = 0 costs n = 1's 155 967; beyond the contract's bound of 512 records, 512's
    4 502 649."""
    sim = im.Simulation(_config(2, period=1000), 1)
    assert blocks.deposit_gas(sim._view, 10.0) == pytest.approx(233_513.5)
    assert blocks.deposit_gas(sim._view, 0.0) == 155_967.0
    assert blocks.deposit_gas(sim._view, 1024.0) == 4_502_649.0


# ---- the instant ledger is the chain's limit ---------------------------------------------------------------

def _same(a, b):
    assert a.robots.equals(b.robots)
    assert a.events.equals(b.events)
    assert a.payments.equals(b.payments)
    assert a.history.equals(b.history)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**63 - 1), experiment=st.sampled_from(["fig4C", "fig2A"]))
def test_block_period_one_over_a_zero_latency_backbone_is_the_instant_ledger(seed, experiment):
    """P = 1, a backbone of zero latency, no loss, no gas: every transaction is in the block made at the
    end of its step, which every robot has before the next step, so the chain model gives the instant
    ledger's results bit for bit (wealth, events, payments, history)."""
    cfg = im.load_experiment(experiment)
    chained = cfg.model_copy(update={"chain": cfg.chain.model_copy(update={"consensus": "poa", "backbone": True})})
    a = im.Simulation(cfg, seed, record_events=True, history_every=100).run(1500)
    b = im.Simulation(chained, seed, record_events=True, history_every=100).run(1500)
    _same(a, b)
    assert b.totals["chain"]["blocks"] == 1500 and b.totals["chain"]["forks"] == 0


def test_the_bench_chain_setup_is_fig4C_with_gossip_only_blocks():
    from infomarket.bench.setups import bench_config

    cfg = bench_config("fig4C+chain", 200)
    base = bench_config("fig4C", 200)
    assert cfg.chain.enabled and not cfg.chain.backbone and cfg.chain.period == 10
    assert cfg.model_copy(update={"chain": base.chain}) == base and not base.chain.enabled


def test_the_swarm_size_bench_runs_every_robot_as_a_node_with_25_signers():
    """``bench --robots N --chain`` (docs/chain-model.md, "Speed"): the bench's chain section with the first
    25 robots as signers (all of them below 25), at the paper's density."""
    from infomarket.bench.setups import CHAIN_BENCH, chain_at
    from infomarket.bench.swarm import scaled_config

    assert chain_at(10) == {**CHAIN_BENCH, "signers": list(range(10))}
    cfg = scaled_config(60, 40, chain=chain_at(60))
    assert cfg.chain.enabled and cfg.chain.signers == list(range(25)) and cfg.swarm.robots == 60
    sim = im.Simulation(cfg, 3)
    sim.run()
    assert set(sim.world.blk_signer[sim.world.blk_live].tolist()) <= set(range(25)) | {-1}
    assert sim.chain_measures()["blocks"] >= 25 * (40 // 15)  # every signer makes one at least every 15 steps
