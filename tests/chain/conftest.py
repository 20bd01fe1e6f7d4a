"""Shared fixtures: one in-process chain per session, robots with their own keys, fresh markets.

``INFOMARKET_CHAIN_ARTIFACT`` points the market fixtures at another compiled artifact: the mutation
check (tests/chain/mutation.py) uses it to run the attack tests against patched contracts.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from infomarket.chain.market import ChainMarket, MarketParams, connect, derived_account, fund_gas
from infomarket.chain.units import to_units

ROBOTS = 8


@pytest.fixture(scope="session")
def artifact() -> dict | None:
    path = os.environ.get("INFOMARKET_CHAIN_ARTIFACT")
    return json.loads(Path(path).read_text()) if path else None


@pytest.fixture(scope="session")
def w3():
    return connect()


@pytest.fixture(scope="session")
def robots(w3):
    accounts = [derived_account("test-robot", i) for i in range(ROBOTS)]
    fund_gas(w3, [a.address for a in accounts])
    return accounts


@pytest.fixture(scope="session")
def make_market(w3, robots, artifact):
    """Factory: a fresh market with every robot granted ``wealth`` tokens."""

    def make(scheme: str = "outlier", *, stake: float = 0.04, wealth: float | list[float] = 1.0,
             theta_deg: float = 30.0, max_contributors: int = 256) -> ChainMarket:
        params = MarketParams.from_floats(scheme, stake=stake, theta_deg=theta_deg,
                                          max_contributors=max_contributors)
        market = ChainMarket.deploy(params, w3=w3, artifact=artifact)
        wealths = wealth if isinstance(wealth, list) else [wealth] * len(robots)
        for account, amount in zip(robots, wealths):
            if amount:
                market.grant_wealth(account.address, to_units(amount))
        return market

    return make
