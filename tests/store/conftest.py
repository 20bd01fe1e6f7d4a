"""A tiny sweep (2 conditions x 3 runs of 6 robots, 300 steps) to damage, lock and resume."""
from pathlib import Path

import pytest

TINY = """
name = "tiny"
steps = {steps}
runs = {runs}
seed = {seed}

[swarm]
robots = 6

[[swarm.groups]]
behaviour = "naive"
count = 5

[[swarm.groups]]
behaviour = "saboteur"
count = 1

[sweep.grid]
"payment.information_share" = [0.25, 0.5]
"""


@pytest.fixture
def tiny(tmp_path) -> "callable":
    """tiny(runs=3, seed=1, steps=300) -> path of the experiment file (rewritten in place)."""

    def make(runs: int = 3, seed: int = 1, steps: int = 300) -> Path:
        p = tmp_path / "tiny.toml"
        p.write_text(TINY.format(runs=runs, seed=seed, steps=steps))
        return p

    return make
