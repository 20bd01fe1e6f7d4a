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


def _weights(records, directions, theta=30.0, grace=1.0):
    """The rule's weights for buyer 0's trip of food records from sellers 1, 2, 3 at ``directions``, with
    the buyer's outcome records ``{seller: (good, bad)}``."""
    h = Handle(make_config(4, scheme="outcome_slash", payment={"stake": 0.04, "reward": 1.0,
                                                               "information_share": 0.5}))
    w = h.world
    a = w.tx_off[0]
    for x, d in enumerate(directions):
        w.tx_seller[a + x], w.tx_site[a + x], w.tx_dir[a + x], w.tx_stake[a + x] = x + 1, 0, d, 0.04
    w.tx_count[0] = len(directions)
    w.pot[0] = 0.04 * len(directions)
    for s, (good, bad) in records.items():
        trust_add(h.view, 0, s, good, bad)
    weights = np.zeros(len(directions))
    get_payment("outcome_slash").weights.func(0, w.tx_seller[a:a + 3], w.tx_site[a:a + 3], w.tx_dir[a:a + 3],
                                              weights, h.view, theta, grace)
    return weights


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


def test_on_a_ledger_alone_every_seller_is_unjudged():
    # replayed without a swarm (no outcome records): the same trip pays stakes back plus 0.2, 0.2, 0.1
    events = [LedgerEvent("purchase", 0, s, 0, d) for s, d in ((1, 10.0), (2, 20.0), (3, 100.0))]
    out = replay_events(events + [LedgerEvent("deposit", 0)], 4, scheme="outcome_slash", stake=0.04)
    assert list(out.balances) == pytest.approx([1 + 1 + 0.12 - 0.62, 1.2, 1.2, 1.1], abs=1e-12)


def test_the_rule_passes_the_public_checker():
    checks.check_payment("outcome_slash")


@pytest.mark.parametrize("params, text", [({"grace": 0.0}, "> 0"), ({"theta": 200.0}, "in [0, 180]")])
def test_bad_parameters_are_refused_by_name(params, text):
    from infomarket.errors import ConfigError

    with pytest.raises(ConfigError) as e:
        make_config(3, scheme="outcome_slash", payment={"params": params})
    assert text in str(e.value) and list(params)[0] in str(e.value)
