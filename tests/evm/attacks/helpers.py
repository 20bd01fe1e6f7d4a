"""What the exploit tests share: a sale whose seller vector points at a chosen direction."""
from __future__ import annotations

import math

import pytest

from infomarket.evm.errors import ContractRevert
from infomarket.evm.protocol import FOOD, PathInfo

#: Where every seller stands in its buyer's frame, and how long its vector is.
POSITION = (0.5, 0.5)
LENGTH = 7.0


def sell(market, seller, buyer, direction: float = 10.0, age: int = 0, site: int = FOOD):
    """``seller`` sells ``buyer`` a record whose seller vector points at ``direction`` degrees."""
    rad = math.radians(direction)
    info = PathInfo.from_floats(POSITION[0] + LENGTH * math.cos(rad), POSITION[1] + LENGTH * math.sin(rad))
    lc = market.light_contract(seller, buyer, site, age, info, POSITION)
    return market.reveal(seller, lc, info)


def settle_all(market, robot: str, batch: int, sender=None) -> list:
    """Call ``settle`` until ``robot``'s settlement completes; the results."""
    results = []
    while market.pending_settlement(robot)[0]:
        results.append(market.settle(robot, batch, sender=sender))
    return results


def refused(call, name: str, **expected) -> None:
    """``call()`` reverts with the contract's custom error ``name`` and exactly these arguments."""
    with pytest.raises(ContractRevert) as info:
        call()
    assert (info.value.name, info.value.args_by_name) == (name, expected)
