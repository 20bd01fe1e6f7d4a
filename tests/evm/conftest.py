"""Shared fixtures: one in-process chain per backend and session, robots with their own keys, fresh
markets.

Every test that uses ``chain`` runs on both in-process backends: revm (fast) and py-evm (the pure-Python
reference EVM), through the same client. ``INFOMARKET_CHAIN_BACKENDS`` (comma-separated) narrows that
list. ``INFOMARKET_CHAIN_ARTIFACT`` points the market fixtures at another compiled artifact: the
mutation check (tests/evm/mutation.py) uses it to run the attack tests against patched contracts.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from infomarket.evm.market import ChainMarket, MarketParams, connect, derived_account
from infomarket.evm.units import to_units

ROBOTS = 8
BACKENDS = os.environ.get("INFOMARKET_CHAIN_BACKENDS", "revm,py-evm").split(",")


@pytest.fixture(scope="session")
def artifact() -> dict | None:
    path = os.environ.get("INFOMARKET_CHAIN_ARTIFACT")
    return json.loads(Path(path).read_text()) if path else None


@pytest.fixture(scope="session", params=BACKENDS)
def chain(request):
    return connect(backend=request.param)


@pytest.fixture(scope="session")
def robots(chain):
    accounts = [derived_account("test-robot", i) for i in range(ROBOTS)]
    chain.fund([a.address for a in accounts])
    return accounts


@pytest.fixture(scope="session")
def make_market(chain, robots, artifact):
    """Factory: a fresh market with every robot granted ``wealth`` tokens."""

    def make(scheme: str = "outlier", *, stake: float = 0.04, wealth: float | list[float] = 1.0,
             theta_deg: float | None = None, **options) -> ChainMarket:
        params = MarketParams.from_floats(scheme, stake=stake, theta_deg=theta_deg, **options)
        market = ChainMarket.deploy(params, backend=chain, artifact=artifact)
        wealths = wealth if isinstance(wealth, list) else [wealth] * len(robots)
        for account, amount in zip(robots, wealths):  # registers every robot, with or without wealth
            market.grant_wealth(account, to_units(amount))
        return market

    return make
