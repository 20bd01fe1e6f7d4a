"""How often the search finds the planted weakness, per seed (docs/attack-search.md, "A known weakness").
Not a test: a measurement over seeds that the test (``test_planted.py``, one declared seed) cannot make.

    python -m tests.search.planted_rates BUDGET SEEDS [SETTINGS_JSON]
    python -m tests.search.planted_rates 96 2,3,4,5,6,7,8,9
    python -m tests.search.planted_rates 256 2,3,4,5,6,7 '{"popsize": 8, "restarts": 4, "runs": 8,
        "finalists": 8, "race": [8, 16, 32], "confirmation_runs": 32}'

One JSON line per seed: the effective rotation of the search's chosen attack, the confirmation medians of
the search's, the random search's, the far baseline's and the truthful reference's attack, and the test's
two criteria (``found``: 15-33 degrees and 0.8 items below the reference; ``beats_random``: 0.3 below it).
"""
import json
import sys
import tempfile
import time
from pathlib import Path

from tests.search import test_planted as planted


def measure(budget: int, seed: int, **settings) -> dict:
    t0 = time.process_time()
    with tempfile.TemporaryDirectory() as folder:
        r = planted.run_planted(Path(folder), budget=budget, seed=seed, **settings)
    rotation = planted.effective_rotation(r.params[r.chosen["search"]])
    row = {"seed": seed, "budget": budget, "rotation": round(rotation, 1),
           **{role: planted._median(r, role) for role in ("search", "random", "baseline", "reference")},
           "cpu_s": round(time.process_time() - t0, 1)}
    row["found"] = bool(15.0 <= rotation < 33.0 and row["search"] <= row["reference"] - 0.8)
    row["beats_random"] = bool(row["search"] < row["random"] - 0.3)
    return row


if __name__ == "__main__":
    budget, seeds = int(sys.argv[1]), [int(s) for s in sys.argv[2].split(",")]
    settings = json.loads(sys.argv[3]) if len(sys.argv) > 3 else {}
    for s in seeds:
        print(json.dumps(measure(budget, s, **settings)), flush=True)
