"""From experiment files to a plan of runs: sweep conditions, their configurations and seeds.

A condition is one point of a sweep's grid × axes.  Its id (``key=value,...``, sorted) names it in the
results store, and its seed stream is derived from (master seed, hash of that id, run index) with
``SeedSequence``: adding values to a grid never changes the seeds of existing conditions, and any run
can be rerun alone (``simulate(condition_config, seed=run_seed)``) with the numbers it had in the sweep.
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
from dataclasses import dataclass, field
from typing import Any

from ..config.load import validate
from ..config.schema import Experiment
from ..seeds import run_seed
from ..errors import ConfigError
from .design import design_data, make_design
from .keypaths import label, set_path

BASE = "base"


@dataclass(frozen=True)
class Condition:
    """One configuration of an experiment, with the keys that distinguish it."""

    experiment: str
    id: str
    keys: dict[str, Any]
    config: Experiment
    runs: int
    master_seed: int
    number: int = field(default=0)  # the seed stream's condition index
    design: Any = field(default=None, compare=False, repr=False)  # runner.design.Design of a sampled sweep

    def seed(self, run: int) -> int:
        """The seed of run ``run`` of this condition: ``seeds.run_seed`` of the master seed, the run and the
        condition's number (a ``SeedSequence`` keyed by both, so each run has a stream of its own)."""
        return run_seed(self.master_seed, run, self.number)


def condition_number(cid: str) -> int:
    """Stable integer for a condition id (0 for the base condition, as ``infomarket run`` uses)."""
    if cid == BASE:
        return 0
    return int(hashlib.sha256(cid.encode()).hexdigest()[:15], 16)


def conditions(exp: Experiment, *, runs: int | None = None, seed: int | None = None,
               scale: float = 1.0) -> list[Condition]:
    """Expand an experiment into its conditions (one, ``base``, when it has no sweep)."""
    master = exp.seed if seed is None else seed

    def n_runs(default: int) -> int:
        n = runs or default
        return max(2, round(n * scale)) if scale != 1.0 else n

    if exp.sweep is None:
        return [Condition(exp.name, BASE, {}, exp, n_runs(exp.runs), master, 0)]
    sw = exp.sweep
    if sw.sample is not None:
        return _sampled(exp, master, n_runs(sw.runs or exp.runs))
    labels = [label(p) for p in sw.grid] + list(sw.axes)
    dupes = {x for x in labels if labels.count(x) > 1}
    if dupes:
        raise ConfigError(f"{exp.name}: sweep keys {sorted(dupes)} would name two columns the same")
    base = exp.model_dump(exclude={"sweep"})
    grid_items = list(sw.grid.items())
    axis_items = list(sw.axes.items())
    out = []
    for combo in itertools.product(*[v for _, v in grid_items], *[v for _, v in axis_items]):
        data = copy.deepcopy(base)
        keys: dict[str, Any] = {}
        for (path, _), value in zip(grid_items, combo[:len(grid_items)]):
            set_path(data, path, value, f"{exp.name}: sweep.grid")
            keys[label(path)] = value
        for (name, _), av in zip(axis_items, combo[len(grid_items):]):
            for path, value in av.set.items():
                set_path(data, path, value, f"{exp.name}: sweep.axes.{name}")
            keys[name] = av.value
        cid = ",".join(f"{k}={json.dumps(keys[k]) if isinstance(keys[k], str) else keys[k]}"
                       for k in sorted(keys)).replace('"', "")
        try:
            cfg = validate(data, f"{exp.name} [{cid}]")
        except ConfigError as exc:
            raise ConfigError(str(exc)) from None
        out.append(Condition(exp.name, cid, keys, cfg, n_runs(sw.runs or exp.runs), master,
                             condition_number(cid)))
    return out


def _sampled(exp: Experiment, master: int, runs: int) -> list[Condition]:
    """One condition ``point=i`` per row of the experiment's sampled design (``runner.design``)."""
    design = make_design(exp, master)
    out = []
    for keys, data in design_data(exp, design):
        cid = f"point={keys['point']}"
        try:
            cfg = validate(data, f"{exp.name} [{cid}]")
        except ConfigError as exc:
            raise ConfigError(str(exc)) from None
        out.append(Condition(exp.name, cid, keys, cfg, runs, master, condition_number(cid), design))
    return out
