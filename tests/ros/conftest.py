"""One Hardhat node for every ROS 2 swarm test of a test process (each swarm deploys its own contract)."""
from __future__ import annotations

import pytest

from ..evm.node import running_node


@pytest.fixture(scope="session")
def rpc():
    with running_node() as url:
        yield url
