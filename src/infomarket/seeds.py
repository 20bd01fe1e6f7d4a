"""Seeds: every run's seed is derived from a master seed with numpy's SeedSequence, so any single run
can be rerun alone (``simulate(config, seed=run_seed)``) and gives the numbers it gave in a batch."""
from __future__ import annotations

import numpy as np

#: The largest seed anywhere (experiment files, the command line, the API, the viewer): numpy's
#: SeedSequence takes any non-negative integer, and 63 bits keep every seed a signed 64-bit integer in
#: Parquet and in DuckDB.
MAX_SEED = 2**63 - 1


def run_seed(master: int, run: int, condition: int = 0) -> int:
    """The 63-bit seed of run ``run`` of condition ``condition`` under ``master``."""
    ss = np.random.SeedSequence(int(master), spawn_key=(int(condition), int(run)))
    return int(ss.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))
