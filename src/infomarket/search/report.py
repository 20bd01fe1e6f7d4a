"""The attack search's answers: held-out comparisons with intervals, the declared rules applied.

Per cell, x is the searched attack (of the re-evaluated candidates, the one with the lowest held-out
median of the objective's loss) and y the best hand-written attack (chosen the same way), both on the
same held-out seeds; the questions are those of ``questions.toml`` (``search_no_worse``,
``search_more_damaging``, ``worst_case_growth``, ``bounded_defence``).  Every statistic comes from
``infomarket.analysis.stats``.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ..analysis import stats
from ..errors import InputTypeError
from .driver import CellSearch
from .objective import loss
from .study import DECLARATION, Study


def _pick(held, labels, objective):
    """Of ``labels``, the attack whose held-out median loss is lowest (ties: the first)."""
    med = {a: float(np.median(loss(held[held.attack == a][objective].to_numpy(), objective))) for a in labels}
    return min(labels, key=lambda a: med[a])


def _runs(held, attack, objective):
    return held[held.attack == attack].sort_values("run")[objective].to_numpy(float)


def _comparison_dict(c: stats.Comparison) -> dict:
    d = asdict(c)
    d["effect"] = asdict(c.effect)
    d["text"] = c.describe()
    return d


def analyse(study: Study, results: list[CellSearch]) -> dict:
    """Every cell's comparisons and every declared question's answer (a JSON-ready dict)."""
    s, q = study.settings, study.questions
    obj = s.objective
    sign = 1.0 if obj == "items" else -1.0  # compare in "lower is more damaging" terms
    cells = []
    for r in results:
        held = r.heldout
        hand = [a for a in study.baselines if a != study.reference]
        x_label, y_label = _pick(held, r.searched, obj), _pick(held, hand, obj)
        x, y = sign * _runs(held, x_label, obj), sign * _runs(held, y_label, obj)
        ref = sign * _runs(held, study.reference, obj) if study.reference else None
        best = r.candidates.sort_values(["fitness", "gen", "cand"], kind="stable")
        chosen = best.iloc[int(x_label.removeprefix("search")) - 1]
        cells.append({"defence": r.cell.defence, "byzantines": r.cell.byzantines, "experiment": r.cell.experiment,
                      "evaluations": len(r.candidates), "search": x_label, "hand": y_label,
                      "start_from": r.start_from,
                      "params": {k: float(chosen[k]) for k in chosen.index if k not in ("gen", "cand", "label", "fitness")},
                      "found_at": {"gen": int(chosen.gen), "cand": int(chosen.cand)},
                      "medians": {a: float(np.median(_runs(held, a, obj))) for a in held.attack.unique()},
                      "x": x, "y": y, "ref": ref})
    n = len(cells)
    margin = q.get("search_no_worse", {}).get("margin", 0.05)
    min_effect = q.get("search_more_damaging", {}).get("min_effect", 0.10)
    max_loss = q.get("bounded_defence", {}).get("max_loss", 0.10)
    no_worse = stats.adjust([stats.compare(c["x"], c["y"], alternative="less", shift=-margin * abs(np.median(c["y"])),
                                           label=f"{c['experiment']}: searched < hand-written + margin")
                             for c in cells])
    hand_better = stats.adjust([stats.compare(c["y"], c["x"], alternative="less",
                                              label=f"{c['experiment']}: hand-written < searched") for c in cells])
    more = stats.adjust([stats.compare(c["x"], c["y"], alternative="less", family=n,
                                       declared=-min_effect * abs(np.median(c["y"])),
                                       label=f"{c['experiment']}: searched < hand-written") for c in cells])
    out_cells = []
    for c, a, b, m in zip(cells, no_worse, hand_better, more):
        answer_nw = stats.answer(a.significant, b.significant)
        no_more = (not m.significant) and m.power >= stats.POWER
        row = {k: v for k, v in c.items() if k not in ("x", "y", "ref")}
        row["search_no_worse"] = {"answer": answer_nw, "test": _comparison_dict(a), "reverse": _comparison_dict(b)}
        row["search_more_damaging"] = {"answer": stats.answer(m.significant, no_more), "test": _comparison_dict(m)}
        if c["ref"] is not None:
            e = stats.effect(c["x"], c["ref"])
            med_ref = float(np.median(c["ref"]))
            row["worst_case_growth"] = {"loss": 1.0 - float(np.median(c["x"])) / med_ref if med_ref else math.nan,
                                        "share": c["byzantines"] / study.experiment.swarm.robots,
                                        "effect_vs_truthful": asdict(e)}
        out_cells.append(row)
    bounded = {}
    if study.reference:
        for d in dict.fromkeys(c["defence"] for c in cells):
            mine = [c for c in cells if c["defence"] == d]
            within = stats.adjust([stats.compare(c["x"], c["ref"], alternative="greater",
                                                 shift=max_loss * abs(np.median(c["ref"])),
                                                 label=f"{c['experiment']}: loss < {max_loss:.0%}") for c in mine])
            beyond = stats.adjust([stats.compare(c["x"], c["ref"], alternative="less",
                                                 shift=max_loss * abs(np.median(c["ref"])),
                                                 label=f"{c['experiment']}: loss > {max_loss:.0%}") for c in mine])
            yes = all(w.significant for w in within)
            no = any(b.significant for b in beyond)
            bounded[d] = {"answer": stats.answer(yes, no), "byzantines": [c["byzantines"] for c in mine],
                          "within": [_comparison_dict(w) for w in within],
                          "beyond": [_comparison_dict(b) for b in beyond]}
    return {"objective": obj, "settings": asdict(s), "cells": out_cells, "bounded_defence": bounded}


def write(out: Path, analysis: dict, *, reduced: str = "", wall_seconds: float | None = None,
          steps: int | None = None, transitory: int | None = None) -> list[Path]:
    """``report.json``, ``report.md`` and ``loss.png`` (worst-case loss vs Byzantine share) into ``out``;
    ``steps`` and ``transitory``: the runs' length, recorded so a shortened search reads as one."""
    out = Path(out)
    paths = [out / "report.json", out / "report.md"]
    meta = {"reduced": reduced, "wall_seconds": wall_seconds, "steps": steps, "transitory": transitory}
    paths[0].write_text(json.dumps({**meta, **analysis}, indent=2, default=_json) + "\n")
    paths[1].write_text(markdown(analysis, reduced=reduced, wall_seconds=wall_seconds, steps=steps,
                                 transitory=transitory))
    fig = _figure(analysis, out / "loss.png")
    return paths + ([fig] if fig else [])


def _json(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating,)):
        return float(v)
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise InputTypeError(f"not JSON: {type(v).__name__}")


def markdown(a: dict, *, reduced: str = "", wall_seconds: float | None = None, steps: int | None = None,
             transitory: int | None = None) -> str:
    s = a["settings"]
    lines = ["# Attack search", ""]
    if reduced:
        lines += [f"**REDUCED RUN ({reduced}): not the declared study; no answer here is the study's.**", ""]
    length = "" if steps is None else (f"Runs of {steps} steps, items counted after step {transitory}. "
                                       if transitory is not None else f"Runs of {steps} steps. ")
    lines += [f"{length}Objective: {a['objective']}; CMA-ES popsize {s['popsize']}, {s['budget']} evaluations per cell, "
              f"{s['runs']} runs per candidate (common random numbers per generation), {s['heldout_runs']} held-out "
              f"runs per attack, best {s['best']} re-evaluated."
              + (f" Wall time {wall_seconds:.0f} s." if wall_seconds else ""), "",
              "| defence | Byzantines | best hand-written (median) | searched (median) | HL shift [95 % CI] | "
              "Cliff's δ [95 % CI] | no worse? | more damaging? | loss vs truthful |",
              "|---|---|---|---|---|---|---|---|---|"]
    for c in a["cells"]:
        t = c["search_more_damaging"]["test"]
        e = t["effect"]
        loss_txt = f"{c['worst_case_growth']['loss']:.1%}" if "worst_case_growth" in c else "–"
        lines.append(f"| {c['defence']} | {c['byzantines']} | {c['hand']} ({t['median_y']:.3g}) | {c['search']} "
                     f"({t['median_x']:.3g}) | {e['hl']:+.3g} [{e['hl_low']:.3g}, {e['hl_high']:.3g}] | "
                     f"{e['delta']:+.2f} [{e['delta_low']:.2f}, {e['delta_high']:.2f}] | "
                     f"{c['search_no_worse']['answer']} | {c['search_more_damaging']['answer']} | {loss_txt} |")
    if a["bounded_defence"]:
        lines += ["", "Loss within 10 % at every Byzantine count (bounded_defence): "
                  + "; ".join(f"{d}: {v['answer']}" for d, v in a["bounded_defence"].items())]
    lines += ["", "Searched parameters per cell (CMA-ES started at the best hand-written attack on the start seeds):", ""]
    for c in a["cells"]:
        p = ", ".join(f"{k}={v:g}" for k, v in c["params"].items())
        lines.append(f"- {c['defence']}, {c['byzantines']} (started at {c.get('start_from') or 'the centre'}): {p}")
    lines += ["", *DECLARATION.record_markdown()]
    return "\n".join(lines) + "\n"


def _figure(a: dict, path: Path) -> Path | None:
    cells = [c for c in a["cells"] if "worst_case_growth" in c]
    if not cells:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for d in dict.fromkeys(c["defence"] for c in cells):
        pts = sorted((c["worst_case_growth"]["share"], c["worst_case_growth"]["loss"]) for c in cells
                     if c["defence"] == d)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=d)
    ax.set_xlabel("Byzantine share")
    ax.set_ylabel("worst-case loss (1 - items / truthful)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
