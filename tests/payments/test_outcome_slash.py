"""Stake slashed by trip outcomes (``outcome_slash``): weights from the buyer's outcome records, by hand.

A buyer's open round trip is written straight into a world's ledger arrays (three food records, each with
a 0.04 stake in the buyer's pot); reward 1 and information share 0.5, so the amount shared is
A = 0.5 + 0.12 = 0.62, and the weights the rule returns are the payouts (they add up to A)."""
import numpy as np
import pytest

from infomarket import checks
from infomarket.behaviours.api import trust_add
from infomarket.ledger import LedgerEvent, replay_events
from infomarket.registry import get_payment

from ..conftest import Handle, make_config


def _paid(scheme, sales, records, *params):
    """Scheme ``scheme``'s weights for buyer 0's round trip of food records ``sales`` = [(seller,
    direction)], with the buyer's outcome records ``{seller: (good, bad)}`` (every failure still due)."""
    h = Handle(make_config(5, scheme=scheme, payment={"stake": 0.04, "reward": 1.0, "information_share": 0.5}))
    w = h.world
    a, k = w.tx_off[0], len(sales)
    for x, (s, d) in enumerate(sales):
        w.tx_seller[a + x], w.tx_site[a + x], w.tx_dir[a + x], w.tx_stake[a + x] = s, 0, d, 0.04
    w.tx_count[0] = k
    w.pot[0] = 0.04 * k
    for s, (good, bad) in records.items():
        trust_add(h.view, 0, s, good, bad)
    weights = np.zeros(k)
    get_payment(scheme).weights.func(0, w.tx_seller[a:a + k], w.tx_site[a:a + k], w.tx_dir[a:a + k], weights,
                                     h.view, *params)
    return weights


def _weights(records, directions, theta=30.0, grace=1.0):
    """``outcome_slash``'s weights for sellers 1, 2, 3 selling once each at ``directions``."""
    return _paid("outcome_slash", list(zip((1, 2, 3), directions)), records, theta, grace)


def test_failed_trips_slash_the_stake_and_the_share():
    # records (3, 0), (0, 1), (0, 3), grace 1: keep 4/4, 1/2, 1/4; stakes back 0.04 + 0.02 + 0.01 = 0.07.
    # All three within 30 degrees: counts 3 each, shares 3 : 1.5 : 0.75 of the rest 0.55 (of 5.25).
    out = _weights({1: (3.0, 0.0), 2: (0.0, 1.0), 3: (0.0, 3.0)}, [10.0, 20.0, 25.0])
    assert list(out) == pytest.approx([0.04 + 0.55 * 3 / 5.25, 0.02 + 0.55 * 1.5 / 5.25,
                                       0.01 + 0.55 * 0.75 / 5.25], abs=1e-12)
    assert out.sum() == pytest.approx(0.62, abs=1e-12)


def test_grace_softens_the_first_failures():
    # grace 3: (0, 1) keeps 3/4, (0, 3) keeps 3/6; (3, 0) keeps all.  Stakes back 0.04 + 0.03 + 0.02 = 0.09;
    # the rest 0.53 by 3 : 2.25 : 1.5 (of 6.75).
    out = _weights({1: (3.0, 0.0), 2: (0.0, 1.0), 3: (0.0, 3.0)}, [10.0, 20.0, 25.0], grace=3.0)
    assert list(out) == pytest.approx([0.04 + 0.53 * 3 / 6.75, 0.03 + 0.53 * 2.25 / 6.75,
                                       0.02 + 0.53 * 1.5 / 6.75], abs=1e-12)


def test_unjudged_sellers_get_their_stakes_back_and_share_by_agreement():
    # no records: every stake back (0.12); 10 and 20 agree within 30 degrees (count 2 each), 100 alone (1):
    # the 0.5 shared 2 : 2 : 1.
    out = _weights({}, [10.0, 20.0, 100.0])
    assert list(out) == pytest.approx([0.04 + 0.2, 0.04 + 0.2, 0.04 + 0.1], abs=1e-12)


def test_each_failed_trip_of_the_round_trip_voids_one_records_stake():
    # seller 1 sells twice (10, 20) with 1 failure due: each record keeps 1/2; seller 2 once (25), none due:
    # keeps all; seller 3 once (100) with 2 failures due (more than its records): keeps nothing.  Its good
    # trips do not count.  A = 0.5 + 4 * 0.04 = 0.66; stakes back 0.02 + 0.02 + 0.04 = 0.08; the rest 0.58
    # by keep x eq. 7 count: 1/2 * 3, 1/2 * 3, 1 * 3, 0 * 1 (of 6).
    out = _paid("trip_slash", [(1, 10.0), (1, 20.0), (2, 25.0), (3, 100.0)],
                {1: (5.0, 1.0), 3: (0.0, 2.0)}, 30.0)
    assert list(out) == pytest.approx([0.02 + 0.145, 0.02 + 0.145, 0.04 + 0.29, 0.0], abs=1e-12)
    assert out.sum() == pytest.approx(0.66, abs=1e-12)


def test_on_a_ledger_alone_every_seller_is_unjudged():
    # replayed without a swarm (no outcome records): the same trip pays stakes back plus 0.2, 0.2, 0.1
    events = [LedgerEvent("purchase", 0, s, 0, d) for s, d in ((1, 10.0), (2, 20.0), (3, 100.0))]
    out = replay_events(events + [LedgerEvent("deposit", 0)], 4, scheme="outcome_slash", stake=0.04)
    assert list(out.balances) == pytest.approx([1 + 1 + 0.12 - 0.62, 1.2, 1.2, 1.1], abs=1e-12)


@pytest.mark.parametrize("name", ["outcome_slash", "trip_slash"])
def test_the_rules_pass_the_public_checker(name):
    checks.check_payment(name)


@pytest.mark.parametrize("params, text", [({"grace": 0.0}, "> 0"), ({"theta": 200.0}, "in [0, 180]")])
def test_bad_parameters_are_refused_by_name(params, text):
    from infomarket.errors import ConfigError

    with pytest.raises(ConfigError) as e:
        make_config(3, scheme="outcome_slash", payment={"params": params})
    assert text in str(e.value) and list(params)[0] in str(e.value)
