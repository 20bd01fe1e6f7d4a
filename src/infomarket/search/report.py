"""The attack search's answers: the chosen attacks on the confirmation seeds, paired, the declared rules
applied.

Every attack a cell chose (on its selection seeds: the search's best, the random search's best, the best
baseline, the worst of those three, and the truthful reference) ran on one shared set of confirmation
seeds that no other phase touched, so run *i* of each is paired with run *i* of every other, and every
comparison is of per-seed differences (``analysis.paired_runs``): the signed-rank test, the
Hodges-Lehmann estimate with its distribution-free interval, Holm over the question's family, and, for a
"no" that rests on a test not rejecting, its simulated power at the declared smallest effect.

The report reads only the fields a cell's search returns (``cell``, ``confirmation``, ``chosen``,
``params``, ``cost``, ``extra``), so any searcher that fills them is reported the same way.  The loss is
per seed: 1 - items under the worst attack / items of the truthful reference on the same seed, and the
figure draws exactly the estimates and intervals the table prints (``figure_data``).
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, is_dataclass
from pathlib import Path

import numpy as np

from ..analysis import paired_runs as pr
from ..analysis import stats
from ..analysis.declared import size_note
from ..analysis.formats import interval_text, json_ready
from ..analysis.study import Report, drawn
from ..analysis.study import Study as DeclaredStudy
from ..errors import ArgumentError
from ..runner.progress import busy_markdown
from . import decision
from .objective import loss
from .study import DECLARATION, Study

#: the key of the store's record of the study's first run (``driver.record_provenance``)
PROVENANCE = "attack_search"

#: the comparisons of the "does one searcher beat another" questions: (question, x role, y role)
DUELS = (("search_beats_baseline", "search", "baseline"), ("search_beats_random", "search", "random"))
EXTRA_QUESTION = "adaptive_beats_parametric"


def _rule(study: Study, name: str) -> dict:
    q = dict(study.questions.get(name, {}))
    q.setdefault("alpha", stats.ALPHA)
    q.setdefault("power", stats.POWER)
    q.setdefault("confidence", stats.CONFIDENCE)
    q.setdefault("family", "cells")
    return q


def _per_run(frame, attack: str, column: str, runs) -> np.ndarray:
    """``column`` of ``attack`` at each of ``runs`` (one value per run, or a clear error)."""
    rows = frame[frame.attack == attack].drop_duplicates("run").set_index("run")
    missing = sorted(set(runs) - set(rows.index))
    if missing or len(frame[frame.attack == attack]) != len(rows):
        raise ArgumentError(f"confirmation runs of {attack!r}: need exactly one row for each run "
                            f"{min(runs)}..{max(runs)}" + (f" (missing {missing[:5]})" if missing else " (duplicates)"))
    return rows.loc[list(runs), column].to_numpy(float)


def _groups(cells: list[dict], family: str) -> list[list[int]]:
    """Indices of ``cells`` in each Holm family: all cells, or per defence, or per Byzantine count."""
    key = {"cells": lambda c: 0, "defence": lambda c: c["defence"], "byzantines": lambda c: c["byzantines"]}
    if family not in key:
        raise ArgumentError(f"family {family!r}: allowed: {', '.join(key)}")
    out: dict = {}
    for i, c in enumerate(cells):
        out.setdefault(key[family](c), []).append(i)
    return list(out.values())


def _holm(comparisons: list, cells: list[dict], family: str) -> list:
    out = list(comparisons)
    for idx in _groups(cells, family):
        for i, c in zip(idx, pr.adjust([comparisons[i] for i in idx])):
            out[i] = c
    return out


def _row(c: pr.PairedComparison) -> dict:
    return {**asdict(c), "significant": c.significant, "text": c.describe()}


def _duel(xs, ys, cells, rule: dict, label: str) -> list[dict]:
    """x beats y (lower damage value) per cell: yes when shown (Holm), no when not shown although the
    test had the power ``rule["power"]`` at the declared effect, else inconclusive."""
    sizes = {i: len(g) for g in _groups(cells, rule["family"]) for i in g}
    comps = [pr.compare(x, y, alternative="less", declared=-rule["min_effect"] * abs(float(np.median(y))),
                        alpha=rule["alpha"], family=sizes[i], confidence=rule["confidence"],
                        label=f"{c['experiment']}: {label}")
             for i, (x, y, c) in enumerate(zip(xs, ys, cells))]
    level = {}
    for g in _groups(cells, rule["family"]):  # the threshold each comparison's one-sided test was judged at
        level.update(zip(g, decision.holm_levels([comps[i].p for i in g], rule["alpha"])[1]))
    out = []
    for i, (c, x, y) in enumerate(zip(_holm(comps, cells, rule["family"]), xs, ys)):
        no = (not c.significant) and c.power >= rule["power"]
        med = float(np.median(y))
        upper = decision.bound(np.asarray(x, float) - np.asarray(y, float), level[i], "upper")
        out.append({"answer": stats.answer(c.significant, no), **_row(c),
                    "level": level[i], "upper": upper, "percent_upper": _pct(upper, med),
                    "percent": _pct(c.hl, med), "percent_low": _pct(c.high, med), "percent_high": _pct(c.low, med)})
    return out


def _pct(v: float, ref: float) -> float:
    """A difference ``v`` of damage values as a share of ``|ref|``, signed so that more damage (a
    negative difference) is positive."""
    return -v / abs(ref) if ref else math.nan


def analyse(study: Study, results: list) -> dict:
    """Every cell's paired comparisons on its confirmation seeds and every declared question's answer (a
    JSON-ready dict).  ``results``: one search result per cell (``driver.CellSearch``)."""
    s = study.settings
    obj = s.objective
    cells, frames, extras = [], [], []
    for r in results:
        conf, chosen = r.confirmation, dict(r.chosen)
        runs = sorted(int(v) for v in conf.run.unique())
        if len(runs) < 2:
            raise ArgumentError(f"{r.cell.experiment}: {len(runs)} confirmation run(s); a paired comparison needs 2")
        damage = {role: loss(_per_run(conf, a, obj, runs), obj) for role, a in chosen.items()}
        items = {role: _per_run(conf, a, "items", runs) for role, a in chosen.items()}
        extra = {name: loss(_per_run(df, _only(df, name), obj, runs), obj)
                 for name, df in (getattr(r, "extra", None) or {}).items()}
        cost = {ph: dict(v) for ph, v in (r.cost or {}).items()}
        cand = getattr(r, "candidates", None)
        evaluations = ({str(k): int(v) for k, v in cand.searcher.value_counts(sort=False).items()}
                       if cand is not None and "searcher" in getattr(cand, "columns", ()) else {})
        cells.append({"defence": r.cell.defence, "byzantines": r.cell.byzantines, "experiment": r.cell.experiment,
                      "share": r.cell.byzantines / study.experiment.swarm.robots, "runs": len(runs),
                      "chosen": chosen,
                      "params": {a: dict(r.params.get(a, {})) for a in dict.fromkeys(chosen.values())},
                      "medians": {role: float(np.median(v)) for role, v in items.items()},
                      "extra_attacks": {n: _only(df, n) for n, df in (getattr(r, "extra", None) or {}).items()},
                      "evaluations": evaluations, "cost": cost, "cost_total": _total(cost), "done": r.done,
                      "skipped": r.skipped})
        frames.append((damage, items, extra))
        extras.append({name: _per_run(df, _only(df, name), "items", runs)
                       for name, df in (getattr(r, "extra", None) or {}).items()})
    out = {"objective": obj, "settings": _settings(s), "cells": cells}
    if not cells:
        return {**out, "bounded_by_defence": {}}
    out["size_note"] = size_note(getattr(s, "confirmation_runs", None), [c["runs"] for c in cells])
    if all("reference" in c["chosen"] for c in cells):
        _decide(study, cells, frames, extras)
        out["bounded_by_defence"] = _by_defence(cells)
    for q, xr, yr in DUELS:
        if all(xr in c["chosen"] and yr in c["chosen"] for c in cells):
            rule = _rule(study, q)
            rule.setdefault("min_effect", 0.05)
            for c, a in zip(cells, _duel([d[xr] for d, _, _ in frames], [d[yr] for d, _, _ in frames], cells,
                                         rule, f"{xr} - {yr}")):
                c[q] = a
    names = sorted({n for _, _, e in frames for n in e})
    for n in names:
        have = [i for i, (_, _, e) in enumerate(frames) if n in e and "search" in cells[i]["chosen"]]
        rule = _rule(study, EXTRA_QUESTION)
        rule.setdefault("min_effect", 0.05)
        sub = [cells[i] for i in have]
        for i, a in zip(have, _duel([frames[i][2][n] for i in have], [frames[i][0]["search"] for i in have], sub,
                                    rule, f"{n} - search")):
            cells[i].setdefault(EXTRA_QUESTION, {})[n] = a
    return out


def _confirmed(items: dict, extra_items: dict) -> dict[str, np.ndarray]:
    """Every confirmed attack of a cell by role (the reference and the selection's "worst" pointer left
    out), the extra searchers (the adaptive attacker) among them: items per run."""
    out = {r: v for r, v in items.items() if r not in ("reference", "worst")}
    return {**out, **extra_items}


def _decide(study: Study, cells: list[dict], frames: list, extras: list[dict]) -> None:
    """``worst_case_bounded`` per cell, decided over every confirmed role (``decision.bounded``), and which
    roles are confirmed more damaging than the search's own attack (Holm over the family's cells x roles)."""
    rule = _rule(study, "worst_case_bounded")
    rule.setdefault("max_loss", 0.10)
    # the per-seed loss is undefined on a seed where the reference collected nothing (a run too short to
    # count items): such a cell is left unanswered, and out of the Holm family
    zero = [int(np.sum(it["reference"] <= 0)) for _, it, _ in frames]
    ok = [i for i, z in enumerate(zero) if z == 0]
    roles = [_confirmed(frames[i][1], extras[i]) for i in range(len(cells))]
    losses = [{r: 1.0 - v / frames[i][1]["reference"] for r, v in roles[i].items()} for i in ok]
    groups = [[ok.index(i) for i in g if i in ok] for g in _groups(cells, rule["family"])]
    for i, b in zip(ok, decision.bounded(losses, [g for g in groups if g], rule["max_loss"], rule["alpha"])):
        if not b["roles"]:
            cells[i]["worst_case_bounded"] = {**b, "loss": math.nan, "low": math.nan, "high": math.nan}
            cells[i]["bounded"] = b["answer"]
            continue
        w = b["roles"][b["worst"]["role"]]
        labels = {**cells[i]["chosen"], **cells[i]["extra_attacks"]}
        for r, v in b["roles"].items():
            v["attack"] = labels.get(r, r)
        cells[i]["worst_case_bounded"] = {**b, "loss": w["loss"], "low": w["interval"][0], "high": w["interval"][1]}
        cells[i]["worst"] = dict(b["worst"])
        cells[i]["roles"] = {r: {"attack": v["attack"], "loss": v["loss"], "interval": list(v["interval"])}
                             for r, v in b["roles"].items()}
        cells[i]["bounded"] = b["answer"]
    for i, z in enumerate(zero):
        if z:
            cells[i]["worst_case_bounded"] = {
                "answer": stats.INCONCLUSIVE, "max_loss": rule["max_loss"], "loss": math.nan, "low": math.nan,
                "high": math.nan, "note": f"the truthful reference collected no items on {z} of "
                                          f"{cells[i]['runs']} seeds: the per-seed loss is undefined"}
            cells[i]["bounded"] = stats.INCONCLUSIVE
    for idx in _groups(cells, rule["family"]):
        damage = {i: {**{r: v for r, v in frames[i][0].items() if r not in ("reference", "worst")}, **frames[i][2]}
                  for i in idx}
        pairs = [(i, r, p) for i in idx for r, p in decision.dominated(damage[i])]
        rejected, _ = decision.holm_levels([p for _, _, p in pairs], rule["alpha"])
        for i in idx:
            if "search" in damage[i]:
                cells[i]["more_damaging_than_search"] = [r for (j, r, _), y in zip(pairs, rejected) if j == i and y]


def _only(df, name: str) -> str:
    labels = list(dict.fromkeys(df.attack))
    if len(labels) != 1:
        raise ArgumentError(f"extra searcher {name!r}: its confirmation runs must hold one attack, not {labels}")
    return labels[0]


def _total(cost: dict) -> dict:
    keys = ("runs", "env_steps", "seconds")
    return {k: sum(float(v.get(k, 0)) for v in cost.values()) for k in keys}


def _settings(s) -> dict:
    return asdict(s) if is_dataclass(s) else dict(s)


def _by_defence(cells: list[dict]) -> dict:
    """Per defence: within the margin at every count (yes: every cell yes; no: some cell no)."""
    out = {}
    for d in dict.fromkeys(c["defence"] for c in cells):
        mine = [c for c in cells if c["defence"] == d]
        ans = [c["worst_case_bounded"]["answer"] for c in mine]
        out[d] = {"answer": stats.answer(all(a == stats.YES for a in ans), any(a == stats.NO for a in ans)),
                  "byzantines": [c["byzantines"] for c in mine], "answers": ans}
    return out


# ------------------------------------------------------------------------------------------ output
def figure_data(analysis: dict) -> dict[str, dict[str, list[float]]]:
    """What the figure draws, per defence: Byzantine share, the worst case's loss (Hodges-Lehmann of the
    per-seed loss) and its interval, and the search's damage beyond the best baseline (as a share of the
    baseline's median) with its interval: the very numbers the table prints."""
    out: dict = {}
    for c in sorted(analysis["cells"], key=lambda c: c["share"]):
        d = out.setdefault(c["defence"], {k: [] for k in ("share", "loss", "low", "high", "beyond", "beyond_low",
                                                          "beyond_high")})
        b = c.get("worst_case_bounded", {})
        s = c.get("search_beats_baseline", {})
        d["share"].append(c["share"])
        for k, v in (("loss", b.get("loss")), ("low", b.get("low")), ("high", b.get("high")),
                     ("beyond", s.get("percent")), ("beyond_low", s.get("percent_low")),
                     ("beyond_high", s.get("percent_high"))):
            d[k].append(math.nan if v is None else float(v))
    return out


def figure(analysis: dict):
    """Two panels from ``figure_data``: the worst case's loss vs Byzantine share (intervals as error
    bars), and how far the search's attack got beyond the best baseline."""
    import matplotlib  # only when a figure is drawn: matplotlib is slow to import

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = figure_data(analysis)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for name, d in data.items():
        for ax, (y, lo, hi) in zip(axes, (("loss", "low", "high"), ("beyond", "beyond_low", "beyond_high"))):
            v, a, b = (np.asarray(d[k], float) for k in (y, lo, hi))
            err = np.vstack([v - np.where(np.isfinite(a), a, v), np.where(np.isfinite(b), b, v) - v])
            ax.errorbar(d["share"], v, yerr=err, marker="o", capsize=3, label=name)
    margins = {c["worst_case_bounded"]["max_loss"] for c in analysis["cells"] if "worst_case_bounded" in c}
    for m in margins:  # the declared bound the loss is judged against
        axes[0].axhline(m, color="grey", lw=0.8, ls="--")
    axes[0].set_ylabel("worst-case loss (1 - items / truthful, per seed)")
    axes[1].set_ylabel("search beyond best baseline (share of its items)")
    axes[1].axhline(0.0, color="grey", lw=0.8)
    for ax in axes:
        ax.set_xlabel("Byzantine share")
        ax.yaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def write(out: Path, analysis: dict, **meta) -> list[Path]:
    """``report(analysis, **meta)`` written into ``out``; returns the files."""
    return report(analysis, **meta).write(out)


def report(analysis: dict, *, reduced: str = "", wall_seconds: float | None = None,
           steps: int | None = None, transitory: int | None = None, provenance: dict | None = None,
           busy: dict | None = None, header: dict | None = None, records: list[str] | None = None) -> Report:
    """``report.json``, ``report.md`` and ``loss.png``, as a ``Report``; ``steps`` and ``transitory``: the runs'
    length, recorded so a shortened search reads as one; ``provenance``: e.g. the questions file's commit
    and the first run's time, printed as they are; ``header``: ``commit``, ``tree_clean``,
    ``questions_commit`` and ``validation`` (the planted suite's recovery rate per searcher), the first
    keys of ``report.json`` and the first lines of ``report.md``."""
    top = {"commit": None, "tree_clean": None, "questions_commit": None, "validation": {}, **(header or {})}
    meta = {**top, "reduced": reduced, "wall_seconds": wall_seconds, "steps": steps, "transitory": transitory,
            "provenance": provenance or {}, "busy": busy or {}}
    parts: list = [("report.json", json.dumps(json_ready({**meta, **analysis}), indent=2) + "\n"),
                   ("report.md", markdown(analysis, reduced=reduced, wall_seconds=wall_seconds, steps=steps,
                                          transitory=transitory, provenance=provenance, header=top, records=records,
                                          busy=busy))]
    if analysis["cells"]:
        parts.append(("loss.png", drawn(lambda: figure(analysis), dpi=120)))
    return Report(parts)


class AttackSearch(DeclaredStudy):
    """The attack search as a declared study: the searched cells' ``results`` (the driver's, read from and
    made into the store) answered as ``report.json``, ``report.md`` and ``loss.png``, with the store's
    record of the study's first run as its provenance; ``meta``: ``report``'s other arguments."""

    declaration = DECLARATION

    def __init__(self, study: Study, results: list, **meta) -> None:
        self.study, self.results, self.meta = study, results, meta
        self.analysis: dict = {}

    def answer(self, store) -> Report:
        """The report of the results, ``store``'s record of the study's first run as its provenance."""
        self.analysis = analyse(self.study, self.results)
        return report(self.analysis, provenance=store.meta().get(PROVENANCE), **self.meta)


def _role_table(cells: list[dict]) -> list[str]:
    """Every confirmed attack of every cell: its loss, its interval at the decision's levels, and whether
    it is shown beyond the margin or more damaging than the search's own attack."""
    if not any("roles" in c for c in cells):
        return []
    out = ["", "Every confirmed attack (lower bound at the level of its \"beyond the margin\" test, upper bound at "
           "the level of its cell's \"within\" test, both one-sided):", "",
           "| defence | Byz. | role | attack | loss | bounds | levels (beyond / within) | beyond the margin? | "
           "more damaging than the search's? |", "|---|---|---|---|---|---|---|---|---|"]
    for c in cells:
        full = c.get("worst_case_bounded", {}).get("roles", {})
        for r, v in c.get("roles", {}).items():
            f = full.get(r, {})
            more = "yes" if r in c.get("more_damaging_than_search", []) else ("–" if r == "search" else "no")
            out.append(f"| {c['defence']} | {c['byzantines']} | {r} | {v['attack']} | {v['loss']:.1%} | "
                       f"{interval_text(v['interval'][0], v['interval'][1], '.1%')} | "
                       f"{f.get('level_beyond', math.nan):.2g} / {f.get('level_within', math.nan):.2g} | "
                       f"{'yes' if f.get('beyond') else 'no'} | {more} |")
    return out


def header_lines(h: dict) -> list[str]:
    """The code's commit (and whether the tree matched it), the questions file's commit, and the planted
    suite's recovery rate per searcher, as a report's first lines."""
    clean = {True: "clean tree", False: "MODIFIED tree: no commit replays these runs", None: "tree state unknown"}
    lines = [f"Code: commit `{h.get('commit')}` ({clean[h.get('tree_clean')]})"
             + (f"; the store's first run was made at commit `{h['first_run_commit']}`" if h.get("first_run_commit")
                else "") + f". Questions file: commit `{h.get('questions_commit')}`"
             + (" (modified since)" if h.get("questions_modified") else "") + "."]
    v = h.get("validation") or {}
    lines.append("Planted-weakness validation (recovery rate per searcher): "
                 + (", ".join(f"{k} {r:.0%}" for k, r in v.items()) if v else "not run with this report") + ".")
    return [*lines, ""]


def _answer(a: dict | None) -> str:
    if not a:
        return "–"
    return a["answer"] + (f" (power {a['power']:.2f})" if a["answer"] != stats.YES and "power" in a
                          and a["power"] == a["power"] else "")


def _duel_cell(a: dict | None) -> str:
    """A duel as its decision reads it: the estimate and its one-sided upper bound at the level the Holm
    test was judged at (below 0 exactly when "beats" is shown), and the same as a share of the other's median.
    A duel written before those bounds were kept shows its two-sided interval, as it was reported."""
    if not a:
        return "–"
    if "upper" not in a:
        share = ("share undefined" if math.isnan(a["percent"]) else
                 f"{a['percent']:+.1%} {interval_text(a['percent_low'], a['percent_high'], '+.1%')}")
        return f"{a['hl']:+.2f} {interval_text(a['low'], a['high'], '.2f')} ({share})"
    up = a["upper"]
    bound = f"≤ {up:+.2f}" if math.isfinite(up) else ("undefined" if math.isnan(up) else "unbounded")
    share = ("share undefined" if math.isnan(a["percent"]) else f"{a['percent']:+.1%}"
             + (f", at least {a['percent_upper']:+.1%}" if math.isfinite(a["percent_upper"]) else ""))
    return f"{a['hl']:+.2f} ({bound} at {a['level']:.2g}; {share})"


def markdown(a: dict, *, reduced: str = "", wall_seconds: float | None = None, steps: int | None = None,
             transitory: int | None = None, provenance: dict | None = None, header: dict | None = None,
             records: list[str] | None = None, busy: dict | None = None) -> str:
    """The attack search's answers ``a`` as Markdown: objective and settings, the answers from the confirmation
    seeds (each search paired with the baselines), the chosen attacks and the cost; a reduced run says so first."""
    s = a["settings"]
    lines = ["# Attack search", "", *header_lines(header or {})]
    if reduced:
        lines += [f"**REDUCED RUN ({reduced}): not the declared study; no answer here is the study's.**", ""]
    length = "" if steps is None else (f"Runs of {steps} steps, items counted after step {transitory}. "
                                       if transitory is not None else f"Runs of {steps} steps. ")
    lines += [f"{length}Objective: {a['objective']}. Settings: "
              + ", ".join(f"{k} {v}" for k, v in s.items() if k != "objective") + "."
              + (f" Wall time {wall_seconds:.0f} s." if wall_seconds else ""), ""]
    for k, v in (provenance or {}).items():
        lines.append(f"- {k}: {v}")
    if provenance:
        lines.append("")
    if a.get("size_note"):
        lines += [f"Confirmation: {a['size_note']}.", ""]
    lines += ["Every number below is from the CONFIRMATION seeds (never used to choose an attack), paired by "
              "seed. Worst: the most damaging of every confirmed attack (search, random search, baselines, "
              "adaptive), by the Hodges-Lehmann estimate of its per-seed loss 1 − items(attack) / items(truthful). "
              "Within the margin: yes only when EVERY confirmed attack is shown within it (intersection-union, "
              "Holm over the cells), no when ANY is shown beyond it (Holm over cells x attacks); each loss "
              "interval is one-sided bound to one-sided bound at the level its test was judged at (the "
              "per-attack table below). Search − baseline, search − random: Hodges-Lehmann "
              "of the per-seed differences of the objective's damage value (negative: the search's attack "
              "does more damage) with its one-sided upper bound at the level its Holm test was judged at (the "
              "search is shown to beat the other exactly when the bound is below 0), and as a share of the "
              "other's median (positive: more damage; \"at least\": the same bound). A \"no\" to a \"beats\" "
              "question needs the power shown.", "",
              "| defence | Byz. | runs | truthful | worst confirmed (role: attack) | loss [decision-level bounds] "
              "| within 10 %? | "
              "search − best baseline | beats baseline? | search − random | beats random? | runs / CPU s |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in a["cells"]:
        b = c.get("worst_case_bounded")
        loss_txt = "–" if not b else ("undefined" if math.isnan(b["loss"]) else
                                      f"{b['loss']:.1%} {interval_text(b['low'], b['high'], '.1%')}")
        m = c["medians"]
        wr = c.get("worst", {}).get("role")
        worst = f"{wr}: {c['roles'][wr]['attack']}" if wr else "–"
        ref = f"{m['reference']:.2f}" if "reference" in m else "–"
        t = c["cost_total"]
        lines.append(f"| {c['defence']} | {c['byzantines']} | {c['runs']} | {ref} | {worst} | {loss_txt} | "
                     f"{_answer(b)} | {_duel_cell(c.get('search_beats_baseline'))} | "
                     f"{_answer(c.get('search_beats_baseline'))} | {_duel_cell(c.get('search_beats_random'))} | "
                     f"{_answer(c.get('search_beats_random'))} | {t['runs']:.0f} / {t['seconds']:.0f} |")
    lines += _role_table(a["cells"])
    notes = [f"- {c['defence']}, {c['byzantines']}: {c['worst_case_bounded']['note']}" for c in a["cells"]
             if c.get("worst_case_bounded", {}).get("note")]
    if notes:
        lines += ["", *notes]
    extra = sorted({n for c in a["cells"] for n in c.get(EXTRA_QUESTION, {})})
    for n in extra:
        lines += ["", f"**{n} vs the parametric search** (per-seed {n} − search; negative: {n} does more damage):",
                  "", "| defence | Byz. | attack | difference (one-sided bound at its level) "
                  "| beats the parametric search? |",
                  "|---|---|---|---|---|"]
        for c in a["cells"]:
            e = c.get(EXTRA_QUESTION, {}).get(n)
            if e:
                lines.append(f"| {c['defence']} | {c['byzantines']} | {c['extra_attacks'][n]} | {_duel_cell(e)} | "
                             f"{_answer(e)} |")
    if a.get("bounded_by_defence"):
        lines += ["", "Loss within 10 % at every Byzantine count, per defence: "
                  + "; ".join(f"{d}: {v['answer']}" for d, v in a["bounded_by_defence"].items())]
    lines += ["", "## Chosen attacks (on the selection seeds)", ""]
    for c in a["cells"]:
        roles = ", ".join(f"{r} = {lab}" for r, lab in c["chosen"].items())
        ev = ", ".join(f"{k} {v}" for k, v in c.get("evaluations", {}).items())
        lines.append(f"- {c['defence']}, {c['byzantines']}: {roles}" + (f" (evaluations: {ev})" if ev else ""))
        for lab, p in c["params"].items():
            if p:
                lines.append(f"  - {lab}: " + ", ".join(f"{k}={v:g}" for k, v in p.items()))
    lines += ["", "## Cost", "", "| defence | Byz. | phase | runs | env-steps | CPU s |", "|---|---|---|---|---|---|"]
    for c in a["cells"]:
        for ph, v in c["cost"].items():
            lines.append(f"| {c['defence']} | {c['byzantines']} | {ph} | {v.get('runs', 0)} | "
                         f"{v.get('env_steps', 0):.3g} | {v.get('seconds', 0):.0f} |")
    total = {k: sum(c["cost_total"][k] for c in a["cells"]) for k in ("runs", "env_steps", "seconds")}
    lines += ["", f"All cells: {total['runs']:.0f} runs, {total['env_steps']:.3g} env-steps, "
                  f"{total['seconds']:.0f} s of run time.", *(["", busy_markdown(busy).rstrip()] if busy else []),
              "", *(DECLARATION.record_markdown() if records is None else records)]
    return "\n".join(lines) + "\n"
