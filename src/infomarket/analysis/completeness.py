"""Is a store's design complete?  Conditions missing from a shipped experiment, and conditions with fewer
runs than the others, so that no figure or answer is drawn silently from part of its design (after ``store repair``
a damaged part is set aside, and a figure would otherwise lose a condition).

A store does not record the grid it was swept from, but a shipped experiment's grid is known: the
conditions of an experiment in the store are compared with those the shipped file plans (by their keys,
so ``rotation_angle=40`` and ``rotation_angle=40.0`` are one condition).  An experiment whose stored
conditions are not all in the shipped plan was swept from another file and is not judged.  Sampled
designs are checked by the sensitivity analysis itself (``point_outputs``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import pandas as pd

from ..config.load import load_experiment, shipped_experiments
from ..runner.plan import conditions


@dataclass(frozen=True)
class Gap:
    """What an experiment of the store lacks against its shipped plan."""

    experiment: str
    planned: int                 # conditions the shipped file plans
    missing: tuple[str, ...]     # conditions without any completed run
    short: tuple[str, ...]       # conditions with fewer completed runs than the most any condition has
    most: int                    # the most completed runs of one condition

    def describe(self) -> str:
        """One line for the report: which conditions have no runs or too few, and the command that resumes the
        sweep."""
        parts = []
        if self.missing:
            more = f"; and {len(self.missing) - 3} more" if len(self.missing) > 3 else ""
            shown = "; ".join(self.missing[:3]) + more
            parts.append(f"{len(self.missing)} of its {self.planned} conditions have no runs in the store ({shown})")
        if self.short:
            parts.append(f"{len(self.short)} condition(s) have fewer runs than the {self.most} of the others "
                         f"({'; '.join(self.short[:3])}{'; ...' if len(self.short) > 3 else ''})")
        return (f"{self.experiment}: INCOMPLETE: " + " and ".join(parts)
                + f"; resume with `infomarket sweep {self.experiment} --out STORE`")


def _key(cid: str) -> str:
    """A condition id with its numbers written one way (``40`` and ``40.0`` alike)."""
    parts = []
    for part in str(cid).split(","):
        k, eq, v = part.partition("=")
        try:
            v = repr(float(v)) if eq else v
        except ValueError:
            pass
        parts.append(f"{k}{eq}{v}")
    return ",".join(sorted(parts))


def gaps(runs: pd.DataFrame) -> dict[str, Gap]:
    """The incomplete shipped experiments of a runs table (the store's ``runs``), by name."""
    if runs is None or runs.empty or not {"experiment", "condition", "run"} <= set(runs.columns):
        return {}
    ok = runs[runs["status"] == "ok"] if "status" in runs.columns else runs
    shipped = shipped_experiments()
    out = {}
    for name in sorted(set(runs["experiment"])):
        if name not in shipped:
            continue
        exp = load_experiment(name)
        if exp.sweep is not None and exp.sweep.sample is not None:
            continue
        planned = {_key(c.id): c.id for c in conditions(exp)}
        mine = ok[ok["experiment"] == name]
        counts = mine.groupby("condition")["run"].nunique()
        stored = {_key(c) for c in runs.loc[runs["experiment"] == name, "condition"]}
        if not stored <= set(planned):
            continue  # swept from another file of the same name: its plan is not the shipped one
        have = {_key(c): int(n) for c, n in counts.items()}
        missing = tuple(planned[k] for k in planned if k not in have)
        most = max(have.values(), default=0)
        short = tuple(f"{planned[k]}: {n}" for k, n in have.items() if n < most)
        if missing or short:
            out[name] = Gap(name, len(planned), missing, short, most)
    return out


def affected(figure: str, incomplete) -> list[str]:
    """The incomplete experiments a headline row's ``figure`` (e.g. ``7B``, ``3A-C``, ``4A vs 3A``) uses."""
    names = set(incomplete)
    out = []
    for digit, letters in re.findall(r"(\d)([A-D](?:-[A-D])?)?", figure):
        span = ([chr(c) for c in range(ord(letters[0]), ord(letters[-1]) + 1)] if letters else [])
        for cand in [f"fig{digit}"] + [f"fig{digit}{L}" for L in span]:
            if cand in names and cand not in out:
                out.append(cand)
    return out
