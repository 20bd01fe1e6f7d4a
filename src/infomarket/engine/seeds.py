"""Seeds: every run's seed is derived from a master seed with numpy's SeedSequence, so any single run
can be rerun alone (``simulate(config, seed=run_seed)``) and gives the numbers it gave in a batch."""
from __future__ import annotations

import numpy as np

from ..config.schema import MAX_SEED  # noqa: F401  (one definition; re-exported for the engine)


def run_seed(master: int, run: int, condition: int = 0) -> int:
    """The 63-bit seed of run ``run`` of condition ``condition`` under ``master``."""
    ss = np.random.SeedSequence(int(master), spawn_key=(int(condition), int(run)))
    return int(ss.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))
