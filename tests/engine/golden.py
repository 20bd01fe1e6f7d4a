"""Golden digests of the shipped paper experiments: what the engine produced before it was rewritten.

Each case is a shipped experiment (or one condition of a swept one), a run seed and a number of steps;
its digest hashes the robots table, the event log and the wealth history bit for bit.  The expected
digests in ``golden_digests.json`` were recorded by the engine *before* the O(N) rewrite (commit
18b2012) and must never be regenerated to make a failing test pass: a changed digest means changed
science.  Regenerate only for a change that is meant to move the paper's numbers, say why in the
commit, and list the affected cases::

    python -m tests.engine.golden --write            # the fast set (make test)
    python -m tests.engine.golden --write --full     # also the full-length set (-m slow)

Runs are stopped early with ``Simulation(cfg, seed).run(N)`` on the unchanged configuration, never with a
changed ``steps`` key (nor ``simulate(..., steps=N)``, which sets it): the Lévy step-length table is
sized by the configured step count.
"""
from __future__ import annotations

import argparse
import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import infomarket as im
from infomarket.runner.plan import conditions

FILE = Path(__file__).with_name("golden_digests.json")

PAPER = ["fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig3B", "fig3C", "fig4A", "fig4B", "fig4C",
         "fig5", "fig6A", "fig6B"]
#: Fig. 7 conditions covered: below and above Θ, one and three Byzantines, both markets.
FIG7 = ["byzantines=3,market=staking,rotation_angle=20.0", "byzantines=3,market=no_staking,rotation_angle=90.0",
        "byzantines=1,market=staking,rotation_angle=60.0"]


@dataclass(frozen=True)
class Case:
    experiment: str
    condition: str  # "base" or a sweep condition id
    run: int
    steps: int

    @property
    def key(self) -> str:
        return f"{self.experiment}[{self.condition}] run {self.run} steps {self.steps}"


def cases(full: bool = False) -> list[Case]:
    """The fast set: every paper setup, two runs each, up to 15 000 steps (20 000 for the long ones,
    30 000 for Fig. 7 so its counting window is covered).  The full set: every setup at full length."""
    out = []
    for name in PAPER:
        cfg = im.load_experiment(name)
        steps = cfg.steps if full else min(cfg.steps, 15000 if cfg.steps <= 15000 else 20000)
        out += [Case(name, "base", run, steps) for run in ((0, 1, 2) if full else (0, 1))]
    steps7 = im.load_experiment("fig7").steps
    out += [Case("fig7", cid, run, steps7) for cid in FIG7 for run in ((0, 1) if full else (0,))]
    return out


def _config(case: Case):
    exp = im.load_experiment(case.experiment)
    for cond in conditions(exp):
        if cond.id == case.condition:
            return cond.config, cond.seed(case.run)
    raise KeyError(case.key)


def _hash_frame(h, frame) -> None:
    for col in frame.columns:
        values = frame[col]
        arr = np.asarray(values.cat.codes if hasattr(values, "cat") else values)
        h.update(col.encode())
        h.update(str(arr.dtype).encode())
        h.update(np.ascontiguousarray(arr).tobytes())


def digest(case: Case) -> str:
    cfg, seed = _config(case)
    r = im.Simulation(cfg, seed, record_events=True, history_every=cfg.history_every or 500).run(case.steps)
    h = hashlib.sha256()
    for frame in (r.robots, r.events, r.history):
        _hash_frame(h, frame)
    return h.hexdigest()


def load() -> dict[str, str]:
    return json.loads(FILE.read_text())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--write", action="store_true", help="record the digests (see the module docstring)")
    p.add_argument("--full", action="store_true", help="include the full-length set")
    args = p.parse_args()
    digests = load() if FILE.exists() else {}
    for case in cases(False) + (cases(True) if args.full else []):
        d = digest(case)
        print(case.key, d, "" if digests.get(case.key) in (None, d) else "CHANGED")
        digests[case.key] = d
    if args.write:
        FILE.write_text(json.dumps(dict(sorted(digests.items())), indent=1) + "\n")


if __name__ == "__main__":
    main()
