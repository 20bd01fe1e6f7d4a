"""What rules may read about the market: every robot's wealth and the ledger's reputation record.

Buy, sell and payment rules call these with the world ``w`` (a payment rule gets it as its ``market``
argument, see ``registry.register_payment``) and a robot id.  They only read: the record is written by
the ledger alone, when transactions settle (``ledger.kernels.distribute``), so no rule can fake its own
or anyone's reputation.  Every helper is O(1), cheap enough to call per neighbour per step.

The record counts a robot's *sales*: a transaction in which it sold information is **settled** when the
buyer deposits an item, and **reduced** when the payment scheme weighed it 0 or below half the best
weight given to a transaction of the same site in that settlement (an outlier, under outlier
penalisation).
Under delayed payment every weight is equal, so nothing is ever reduced.
"""
from ..jit import njit


@njit(forceinline=True, cache=True)
def wealth(w, j):
    """Robot j's balance (its wealth, as the robots table reports it)."""
    return w.balance[j]


@njit(forceinline=True, cache=True)
def wealth_share(w, j):
    """Robot j's balance as a fraction of all balances (0 when there is no money)."""
    total = w.money[0]
    if total <= 0.0:
        return 0.0
    return w.balance[j] / total


@njit(forceinline=True, cache=True)
def sales_settled(w, j):
    """How many transactions in which j sold information have been settled."""
    return w.rep_settled[j]


@njit(forceinline=True, cache=True)
def sales_reduced(w, j):
    """How many of j's settled sales were weighed as outliers (0, or below half the best of their site)."""
    return w.rep_reduced[j]


@njit(forceinline=True, cache=True)
def seller_reputation(w, j):
    """The fraction of j's settled sales that were not outliers, with one good and one bad sale added
    (Laplace's rule), so a seller nobody has judged yet scores 0.5 and one sale cannot make 0 or 1.
    When the market's reputation decays (``payment.reputation_decay`` < 1) the sales are counted
    decayed: each earlier sale weighs ``reputation_decay`` times less at every later one, so a record
    built long ago does not cover lies told now."""
    if w.rep_decay < 1.0:
        return (w.rep_good[j] + 1.0) / (w.rep_good[j] + w.rep_bad[j] + 2.0)
    return (w.rep_settled[j] - w.rep_reduced[j] + 1.0) / (w.rep_settled[j] + 2.0)


@njit(forceinline=True, cache=True)
def earnings(w, j):
    """Money j has been paid for its settled sales (stakes returned with the payment included)."""
    return w.rep_earned[j]


@njit(forceinline=True, cache=True)
def stake_lost(w, j):
    """Stake j locked in settled sales and did not get back (stake minus payment, where positive)."""
    return w.rep_stake_lost[j]


@njit(forceinline=True, cache=True)
def deposits(w, j):
    """How many items j has deposited (every deposit, the transitory period included)."""
    return w.rep_deposits[j]
