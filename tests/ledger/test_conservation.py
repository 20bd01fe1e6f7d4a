"""Money is conserved over any sequence of purchases and deposits, and no balance goes negative."""
from hypothesis import given, settings
from hypothesis import strategies as st

from infomarket.ledger import LedgerEvent, replay_events

ROBOTS = 5
purchase = st.builds(lambda b, s, site, d: LedgerEvent("purchase", b, (b + s) % ROBOTS, site, d),
                     st.integers(0, ROBOTS - 1), st.integers(1, ROBOTS - 1), st.integers(0, 1),
                     st.floats(0, 359.999))
deposit = st.builds(lambda b: LedgerEvent("deposit", b), st.integers(0, ROBOTS - 1))


@settings(max_examples=60, deadline=None)
@given(events=st.lists(st.one_of(purchase, purchase, deposit), max_size=60),
       scheme=st.sampled_from(["delayed", "outlier"]), stake=st.sampled_from([0.0, 0.04, 0.3]),
       initial=st.sampled_from([0.0, 0.05, 1.0]))
def test_money_is_conserved(events, scheme, stake, initial):
    res = replay_events(events, ROBOTS, scheme=scheme, stake=stake, initial_wealth=initial)
    deposits = sum(e.kind == "deposit" for e in events)
    total = res.balances.sum() + res.pots.sum()
    assert abs(total - (ROBOTS * initial + deposits * 1.0)) < 1e-9
    assert (res.balances >= -1e-12).all() and (res.pots >= 0).all()
