"""Property: any sequence of reveals and buys keeps the token supply exact and the ledger sound.

For random sequences (random buyers, sellers, sites, directions, schemes, capped_outlier with cap 1
beside them, and initial wealth small enough that stakes get refused), after every operation:
- every token is accounted for: balances + locked stakes + bonds == totalSupply == wealth granted +
  rewards;
- the contract accepts exactly the sales the model accepts (a refused one fails with
  InfoMarketInsufficientStake, never with an arithmetic panic), so no balance is ever driven below 0;
- every balance is within its rounding bound of the exact rational model (tests/evm/exact_ledger.py).
"""
from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from infomarket.evm.errors import ContractRevert
from infomarket.evm.protocol import PathInfo
from infomarket.evm.units import TOKEN_UNIT, to_units

from .exact_ledger import SELLER_POSITION, ExactLedger, vector_for

N = 4
SCHEMES = [("delayed", 0.0), ("outlier", 0.0), ("outlier", 0.04)]
#: capped_outlier with cap 1: a seller's second record to a buyer in a round trip is void
CAPPED = ("capped_outlier", 0.04)
WEALTHS = [0.05, 0.1, 1.0]

#: Directions whose pairwise differences stay at least 0.01 degree away from Theta = 30, so that the
#: micro-unit vectors the contract compares decide every pair as the degrees do.
directions = st.sampled_from([0.0, 10.0, 25.0, 29.99, 45.5, 180.0, 209.98, 330.02, 359.9])
sale = st.tuples(st.just("sell"), st.integers(0, N - 1), st.integers(0, N - 1), st.integers(0, 1), directions)
buy = st.tuples(st.just("buy"), st.integers(0, N - 1))
sequences = st.lists(st.one_of(sale, sale, buy), min_size=1, max_size=12)


@pytest.fixture(scope="module")
def deployed(chain, make_market):
    """One market per (scheme, wealth), deployed once; each example starts from this snapshot."""
    markets = {(s, stake, wealth): make_market(s, stake=stake, wealth=[wealth] * N + [0.0] * 4,
                                               **({"cap": 1} if (s, stake) == CAPPED else {}))
               for s, stake in SCHEMES + [CAPPED] for wealth in WEALTHS}
    return markets, chain, chain.snapshot()


#: Random sequences per backend: revm explores the sequences; py-evm, far slower per transaction,
#: checks on a sample that the reference EVM agrees (every transaction of the other tests runs on both).
EXAMPLES = {"revm": 20, "py-evm": 5}


def test_random_sequences_conserve_supply_and_never_go_negative(deployed, robots):
    @settings(max_examples=EXAMPLES.get(deployed[1].name, 20), deadline=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(scheme=st.sampled_from(SCHEMES), wealth=st.sampled_from(WEALTHS), ops=sequences)
    def check(scheme, wealth, ops):
        check_sequence(deployed, robots, scheme, wealth, ops)

    check()


def test_random_capped_sequences_conserve_supply_and_never_go_negative(deployed, robots):
    """Longer runs of sales between deposits than above, so that sellers sell a buyer twice (void)."""
    @settings(max_examples=EXAMPLES.get(deployed[1].name, 20), deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(wealth=st.sampled_from(WEALTHS), ops=st.lists(st.one_of(sale, sale, sale, buy), min_size=6, max_size=12))
    def check(wealth, ops):
        check_sequence(deployed, robots, CAPPED, wealth, ops, cap=1)

    check()


def check_sequence(deployed, robots, scheme, wealth, ops, cap=0):
    """Run ``ops`` on the deployed market of (scheme, wealth) and on the rational model, checking after
    every operation."""
    markets, chain, snapshot = deployed
    chain.revert(snapshot)
    name, stake = scheme
    market = markets[(name, stake, wealth)]
    exact = ExactLedger(N, name, Fraction(1), Fraction(1, 2), Fraction(str(stake)), Fraction(30),
                        Fraction(str(wealth)), cap=cap)
    minted = to_units(wealth) * N
    for age, op in enumerate(ops):
        if op[0] == "buy":
            market.deposit(robots[op[1]].address)
            exact.deposit(op[1])
            minted += TOKEN_UNIT
        else:
            _, buyer, seller, site, direction = op
            if buyer == seller:
                continue
            info = PathInfo.from_floats(*vector_for(direction))
            accepted = exact.purchase(buyer, seller, site, Fraction(str(direction)))
            lc = market.light_contract(robots[seller], robots[buyer], site, age, info, SELLER_POSITION)
            if accepted:
                market.reveal(robots[seller], lc, info)
            else:
                with pytest.raises(ContractRevert) as refused:
                    market.reveal(robots[seller], lc, info)
                assert refused.value.name == "InfoMarketInsufficientStake"

        balances = [market.balance_of(r.address) for r in robots[:N]]
        pots = [market.locked_stake(r.address) for r in robots[:N]]
        bonds = sum(market.bond_of(r.address) for r in robots)  # every robot registered, each bonded
        assert sum(balances) + sum(pots) + bonds == market.total_supply() == minted + bonds
        assert pots == [to_units(float(p)) for p in exact.pot]
        for i in range(N):
            assert exact.balance[i] >= 0
            assert abs(balances[i] - exact.balance[i] * TOKEN_UNIT) < max(exact.bound[i], 1)
