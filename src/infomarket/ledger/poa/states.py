"""Block states: the ledger after a block, kept as a row (``blk_state``) of ``blk_bal`` and ``bs_*`` that
blocks without transactions share with their parent, and the checkpoint's copy (``ck_*``); saving the
ledger arrays into them and loading them back (the invariants they keep: ``ledger.poa``)."""
from ...jit import njit

from ...state.view import unlock


@njit(cache=True)
def save_checkpoint(w):
    """The ledger arrays' state becomes the checkpoint's (``ck_*``).  Its buyers' lists of open
    transactions are not copied: the checkpoint is a live block, whose state keeps them (``bs_list``)."""
    _copy_ledger(w.balance, w.pot, w.burned, w.tx_off, w.tx_cap, w.tx_count, w.pool_top, w.money, w.rep_settled,
                 w.rep_reduced, w.rep_earned, w.rep_stake_lost, w.rep_deposits, w.gas_paid,
                 unlock(w.ck_balance), unlock(w.ck_pot), unlock(w.ck_burned), unlock(w.ck_tx_off),
                 unlock(w.ck_tx_cap), unlock(w.ck_tx_count), unlock(w.ck_pool_top), unlock(w.ck_money),
                 unlock(w.ck_rep_settled), unlock(w.ck_rep_reduced), unlock(w.ck_rep_earned),
                 unlock(w.ck_rep_stake_lost), unlock(w.ck_rep_deposits), unlock(w.ck_gas_paid))


@njit(cache=True)
def _copy_ledger(balance, pot, burned, tx_off, tx_cap, tx_count, pool_top, money, rep_settled, rep_reduced,
                 rep_earned, rep_stake_lost, rep_deposits, gas_paid, o_balance, o_pot, o_burned, o_tx_off, o_tx_cap,
                 o_tx_count, o_pool_top, o_money, o_rep_settled, o_rep_reduced, o_rep_earned, o_rep_stake_lost,
                 o_rep_deposits, o_gas_paid):
    o_balance[:] = balance
    o_pot[:] = pot
    o_burned[:] = burned
    o_tx_off[:] = tx_off
    o_tx_cap[:] = tx_cap
    o_tx_count[:] = tx_count
    o_pool_top[0] = pool_top[0]
    o_money[0] = money[0]
    o_rep_settled[:] = rep_settled
    o_rep_reduced[:] = rep_reduced
    o_rep_earned[:] = rep_earned
    o_rep_stake_lost[:] = rep_stake_lost
    o_rep_deposits[:] = rep_deposits
    o_gas_paid[:] = gas_paid


@njit(cache=True)
def same_state(w, a, b):
    """Do blocks a and b have the same state (the same row: one of them, or a block between, includes no
    transaction)?"""
    return w.blk_state[a] == w.blk_state[b]


@njit(cache=True)
def set_current(w, b):
    """The ledger arrays now hold the state after block b."""
    unlock(w.state_block)[0] = b


@njit(cache=True)
def save_state(w, b):
    """Block b's state (its row of ``blk_bal`` and ``bs_*``, ``blk_state``): the ledger arrays' (they hold the
    state after b), with each buyer's list as its node (``state_list``: nothing is copied)."""
    n = w.balance.shape[0]
    b = w.blk_state[b]
    bal, pot, count, ver = unlock(w.blk_bal), unlock(w.bs_pot), unlock(w.bs_tx_count), unlock(w.bs_list)
    settled, reduced, earned = unlock(w.bs_rep_settled), unlock(w.bs_rep_reduced), unlock(w.bs_rep_earned)
    lost, deposits, gas = unlock(w.bs_rep_stake_lost), unlock(w.bs_rep_deposits), unlock(w.bs_gas_paid)
    for i in range(n):
        bal[b, i] = w.balance[i]
        pot[b, i] = w.pot[i]
        count[b, i] = w.tx_count[i]
        settled[b, i] = w.rep_settled[i]
        reduced[b, i] = w.rep_reduced[i]
        earned[b, i] = w.rep_earned[i]
        lost[b, i] = w.rep_stake_lost[i]
        deposits[b, i] = w.rep_deposits[i]
        gas[b, i] = w.gas_paid[i]
        ver[b, i] = w.state_list[i]
    unlock(w.bs_burned)[b] = w.burned[0]
    unlock(w.bs_money)[b] = w.money[0]


@njit(cache=True)
def load_state(w, b):
    """The ledger arrays get block b's state (``save_state``), except the buyers' lists of open
    transactions, which ``materialise`` copies when they are needed.  ``state_block`` is then b."""
    n = w.balance.shape[0]
    s = w.blk_state[b]
    balance, pot, count = unlock(w.balance), unlock(w.pot), unlock(w.tx_count)
    settled, reduced, earned = unlock(w.rep_settled), unlock(w.rep_reduced), unlock(w.rep_earned)
    lost, deposits, gas = unlock(w.rep_stake_lost), unlock(w.rep_deposits), unlock(w.gas_paid)
    bver = unlock(w.state_list)
    for i in range(n):
        balance[i] = w.blk_bal[s, i]
        pot[i] = w.bs_pot[s, i]
        count[i] = w.bs_tx_count[s, i]
        settled[i] = w.bs_rep_settled[s, i]
        reduced[i] = w.bs_rep_reduced[s, i]
        earned[i] = w.bs_rep_earned[s, i]
        lost[i] = w.bs_rep_stake_lost[s, i]
        deposits[i] = w.bs_rep_deposits[s, i]
        gas[i] = w.bs_gas_paid[s, i]
        bver[i] = w.bs_list[s, i]
    unlock(w.pool_stale)[0] = True
    unlock(w.burned)[0] = w.bs_burned[s]
    unlock(w.money)[0] = w.bs_money[s]
    unlock(w.state_block)[0] = b


@njit(cache=True)
def ledger_at(w, target):
    """Make the ledger arrays hold the state after block ``target``: a copy of the state it keeps
    (``save_state``); nothing is applied again."""
    if not same_state(w, w.state_block[0], target):
        load_state(w, target)
