"""The attack tests' shared fixture: a market with no robot registered yet."""
from __future__ import annotations

import pytest

from infomarket.evm.market import ChainMarket, MarketParams, derived_account


@pytest.fixture
def fresh(chain, artifact):
    """Factory: a market with no robot registered yet, and fresh accounts funded with gas money."""

    def make(scheme="outlier_distinct", stake=0.0, accounts=4, label="trust", **options):
        params = MarketParams.from_floats(scheme, stake=stake, **options)
        market = ChainMarket.deploy(params, backend=chain, artifact=artifact)
        robots = [derived_account(label, i) for i in range(accounts)]
        chain.fund([r.address for r in robots])
        return market, robots

    return make
