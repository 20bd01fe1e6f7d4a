"""Shared fixtures: one in-process chain per backend and session, robots with their own keys, fresh
markets (a market deployed once per configuration and chain, then reverted to: ``Deployments``).

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

from .clients import client_copy

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


class Deployments:
    """``make_market``: a market with every robot granted ``wealth`` tokens, as deployed and granted afresh.

    Deploying and granting is a dozen transactions, slow on py-evm, and most tests ask for one of a few
    configurations; so each configuration's market is kept with a snapshot of the chain taken right
    after it was deployed and granted, and a test's first market is that snapshot reverted to (its
    client copied as it was then) when nothing has changed the chain since the test began and every
    snapshot taken after it is one of these (reverting drops those).  Otherwise, and for a test's later
    markets, it is deployed afresh.  Snapshots and reverts by the tests go through here too."""

    def __init__(self, chain, robots, artifact):
        self.chain, self.robots, self.artifact = chain, robots, artifact
        self.changes = 0
        self.snapshots: list[tuple[object, bool]] = []  # (handle, one of ours), oldest first
        self.kept: dict[tuple, tuple[ChainMarket, object]] = {}
        self.began_at, self.given = None, True
        for name in ("transact", "deploy", "fund", "advance_to"):
            setattr(chain, name, self._counted(getattr(chain, name)))
        self._snapshot, self._revert = chain.snapshot, chain.revert
        chain.snapshot, chain.revert = self.snapshot, self.revert

    def _counted(self, call):
        def counted(*args, **kwargs):
            self.changes += 1
            return call(*args, **kwargs)
        return counted

    def begin(self) -> None:
        self.began_at, self.given = self.changes, False

    def snapshot(self, ours: bool = False):
        handle = self._snapshot()
        self.snapshots.append((handle, ours))
        return handle

    def revert(self, handle) -> None:
        self._revert(handle)
        at = [i for i, (h, _) in enumerate(self.snapshots) if h is handle or h == handle]
        del self.snapshots[at[-1] + 1 if at else 0:]  # one taken before this class: nothing after it is known
        live = [h for h, _ in self.snapshots]
        self.kept = {key: kept for key, kept in self.kept.items() if any(kept[1] is h for h in live)}

    def _revertible(self, handle) -> bool:
        at = [i for i, (h, _) in enumerate(self.snapshots) if h is handle]
        return bool(at) and all(ours for _, ours in self.snapshots[at[-1] + 1:])

    def __call__(self, scheme: str = "outlier", *, stake: float = 0.04, wealth: float | list[float] = 1.0,
                 theta_deg: float | None = None, **options) -> ChainMarket:
        key = (scheme, stake, tuple(wealth) if isinstance(wealth, list) else wealth, theta_deg,
               tuple(sorted(options.items())))
        first, self.given = not self.given and self.changes == self.began_at, True
        if first and key in self.kept and self._revertible(self.kept[key][1]):
            template, handle = self.kept[key]
            self.revert(handle)
            return client_copy(template)
        params = MarketParams.from_floats(scheme, stake=stake, theta_deg=theta_deg, **options)
        market = ChainMarket.deploy(params, backend=self.chain, artifact=self.artifact)
        wealths = wealth if isinstance(wealth, list) else [wealth] * len(self.robots)
        for account, amount in zip(self.robots, wealths):  # registers every robot, with or without wealth
            market.grant_wealth(account, to_units(amount))
        self.kept[key] = (client_copy(market), self.snapshot(ours=True))
        return market


@pytest.fixture(scope="session")
def make_market(chain, robots, artifact) -> Deployments:
    """Factory: a fresh market with every robot granted ``wealth`` tokens (``Deployments``)."""
    return Deployments(chain, robots, artifact)


@pytest.fixture(autouse=True)
def _a_test_begins(request):
    if "make_market" in request.fixturenames:
        request.getfixturevalue("make_market").begin()
