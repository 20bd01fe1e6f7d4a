"""A market client copied as it was: for a test that reverts the chain to a snapshot of a market it
deployed before, so that the client's records (acceptances, keys) are those of that moment."""
from __future__ import annotations

import copy

from infomarket.evm.market import ChainMarket


def client_copy(market: ChainMarket) -> ChainMarket:
    """A client of the same contract with its own copy of what it has recorded (acceptances, keys)."""
    new = copy.copy(market)
    for name, value in vars(market).items():
        if isinstance(value, (dict, list, set)):
            setattr(new, name, copy.copy(value))
    return new
