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


def checked_seed_arg(seed, where: str = "seed") -> int:
    """``seed`` as a seed (an integer in [0, 2**63 - 1], as everywhere), else an ArgumentError naming ``where``."""
    from .errors import ArgumentError  # seeds is imported by the errors' users: no import cycle

    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= MAX_SEED:
        raise ArgumentError(f"{where} must be an integer in [0, 2**63 - 1] (as in experiment files and on the "
                            f"command line), got {seed!r}"[:300])
    return int(seed)
