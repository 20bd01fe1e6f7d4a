"""The defence search's answers: paired comparisons on the confirmation seeds, the frontier, the floor.

Every number a question answers from comes from the confirmation runs (``driver.Result``), where every
confirmed defence and the undefended swarm ran on the same seeds: per seed, the cost
``c = 1 - items / items(undefended)`` and at each count the loss ``l = 1 - items(worst) / items(truthful)``,
each judged by ``analysis.paired_runs`` (signed-rank, Hodges-Lehmann with its interval, Holm).  The
search-phase estimates (``Judged``) only chose what to confirm; they are reported as such.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..analysis import paired_runs as pr
from ..analysis import stats
from ..analysis.formats import interval_text, json_ready
from ..analysis.study import Report, drawn
from ..analysis.study import Study as DeclaredStudy
from ..runner.progress import busy_markdown
from .driver import NAME, Judged, Result, pareto
from .study import DECLARATION, Study, floor

DEFAULTS = {"alpha": stats.ALPHA, "confidence": stats.CONFIDENCE}


def _rule(study: Study, name: str) -> dict:
    return {**DEFAULTS, **study.questions.get(name, {})}


def _ratio_loss(x: np.ndarray, ref: np.ndarray) -> np.ndarray | None:
    """1 - x / ref per seed; None where ref is 0 on some seed (the loss is undefined there)."""
    return None if np.any(ref <= 0) else 1.0 - x / ref


def _interval(v: np.ndarray | None, confidence: float) -> dict:
    if v is None:
        return {"hl": math.nan, "low": math.nan, "high": math.nan,
                "note": "undefined: a reference run collected nothing"}
    low, high, cover = pr.hl_interval(v, confidence)
    return {"hl": pr.hodges_lehmann(v), "low": low, "high": high, "coverage": cover}


def _tests(values: list[np.ndarray | None], margin: float, labels: list[str], rule: dict) -> list[dict]:
    """Per candidate: shown within ``margin`` (H1 v < margin) and shown beyond it (H1 v > margin), each
    Holm-adjusted over the candidates whose value is defined."""
    ok = [i for i, v in enumerate(values) if v is not None]
    kw = {"alpha": rule["alpha"], "confidence": rule["confidence"]}
    within = pr.adjust([pr.compare(values[i], np.zeros_like(values[i]), alternative="less", shift=-margin,
                                   label=f"{labels[i]} < {margin:.0%}", **kw) for i in ok]) if ok else []
    beyond = pr.adjust([pr.compare(values[i], np.zeros_like(values[i]), alternative="greater", shift=-margin,
                                   label=f"{labels[i]} > {margin:.0%}", **kw) for i in ok]) if ok else []
    out = [{"within": False, "beyond": False, "p_within": math.nan, "p_beyond": math.nan} for _ in values]
    for i, w, b in zip(ok, within, beyond):
        out[i] = {"within": w.significant, "beyond": b.significant, "p_within": w.p_adjusted, "p_beyond": b.p_adjusted}
    return out


def voices_floor(judged: Judged, byzantines: int, robots: int) -> float:
    """The floor for a robust buyer's own combination: ``vectors`` purchases from distinct sellers, a share
    ``b / (robots - 1)`` of them liars on average, plus its own entry (honest): f / (n - 2f)."""
    m = judged.candidate.values.get("vectors")
    if m is None:
        return math.nan
    f = m * byzantines / (robots - 1)
    return floor(f, m + 1)


def analyse(study: Study, result: Result) -> dict:
    """Every confirmed candidate's cost and losses with intervals, and every declared question's answer."""
    s = study.settings
    by_label = {j.candidate.label: j for j in result.judged}
    confirmed = [by_label[lab] for lab in result.confirmed]
    labels = [j.candidate.label for j in confirmed]
    rule = _rule(study, "bounded_defence")
    target = int(rule.get("byzantines", s.target))
    max_loss, max_cost = float(rule.get("max_loss", 0.10)), float(rule.get("max_cost", s.max_cost))
    costs, lost, losses = [], [], {b: [] for b in study.byzantines}
    for lab in labels:
        c = result.cost_runs[result.cost_runs.label == lab].sort_values("run")
        costs.append(_ratio_loss(c["items"].to_numpy(float), c.undefended.to_numpy(float)))
        lost.append(c.undefended.to_numpy(float) - c["items"].to_numpy(float))  # items per robot lost
        for b in study.byzantines:
            a = result.attack_runs[(result.attack_runs.label == lab) & (result.attack_runs.byzantines == b)]
            a = a.sort_values("run")
            losses[b].append(_ratio_loss(a.worst.to_numpy(float), a.reference.to_numpy(float)))
    cost_t = _tests(costs, max_cost, [f"{lab}: cost" for lab in labels], rule)
    loss_t = _tests(losses.get(target, [None] * len(labels)), max_loss, [f"{lab}: loss" for lab in labels], rule)
    rows = []
    for i, j in enumerate(confirmed):
        yes = cost_t[i]["within"] and loss_t[i]["within"]
        no = cost_t[i]["beyond"] or loss_t[i]["beyond"]
        rows.append({
            "label": j.candidate.label, "family": j.candidate.family, "origin": j.candidate.origin,
            "values": dict(j.candidate.values), "cost": {**_interval(costs[i], rule["confidence"]), **cost_t[i]},
            "cost_items": _interval(lost[i], rule["confidence"]),
            "loss": {str(b): _interval(losses[b][i], rule["confidence"]) for b in study.byzantines},
            "loss_target": loss_t[i], "answer": stats.answer(yes, no),
            "attacks": {str(b): j.attacks[b] for b in study.byzantines},
            "voices_floor": {str(b): voices_floor(j, b, study.robots) for b in study.byzantines}})
    answers = [r["answer"] for r in rows]
    out = {"target": target, "max_loss": max_loss, "max_cost": max_cost, "runs": s.confirmation_runs,
           "byzantines": list(study.byzantines), "robots": study.robots,
           "floor": {str(b): floor(b, study.robots) for b in study.byzantines},
           "confirmed": rows, "search": _search_rows(study, result.judged, set(labels)),
           "bounded_defence": {"answer": stats.answer(any(a == stats.YES for a in answers),
                                                      bool(answers) and all(a == stats.NO for a in answers)),
                               "yes": [r["label"] for r in rows if r["answer"] == stats.YES]},
           "made": result.made, "found": result.found}
    out["beats_existing"] = _beats_existing(study, confirmed, losses.get(target, []), target)
    return out


def _beats_existing(study: Study, confirmed: list[Judged], losses: list, target: int) -> dict:
    s = study.settings
    rule = {**_rule(study, "beats_existing")}
    rule.setdefault("min_effect", 0.05)
    new = [(j.trade(target, s.max_cost), j.candidate.label, k) for k, j in enumerate(confirmed)
           if j.candidate.origin != "existing" and losses[k] is not None]
    old = [(float(np.median(losses[k])), j.candidate.label, k) for k, j in enumerate(confirmed)
           if j.candidate.origin == "existing" and losses[k] is not None]
    if not new or not old:
        return {"answer": stats.INCONCLUSIVE, "note": "needs a confirmed new defence and a confirmed existing one"}
    (_, nl, nk), (_, ol, ok) = min(new), min(old)
    c = pr.compare(losses[nk], losses[ok], alternative="less", declared=-rule["min_effect"], alpha=rule["alpha"],
                   confidence=rule["confidence"], label=f"loss({nl}) - loss({ol})")
    no = (not c.significant) and c.power >= stats.POWER
    return {"answer": stats.answer(c.significant, no), "new": nl, "existing": ol, "hl": c.hl, "low": c.low,
            "high": c.high, "p": c.p, "power": c.power, "min_effect": rule["min_effect"]}


def _search_rows(study: Study, judged: list[Judged], confirmed: set[str]) -> list[dict]:
    s = study.settings
    front = {id(j) for j in pareto([j for j in judged if j.candidate.origin != "existing"], s.target)}
    return [{"label": j.candidate.label, "family": j.candidate.family, "origin": j.candidate.origin,
             "values": dict(j.candidate.values), "cost": j.cost, "losses": {str(b): v for b, v in j.losses.items()},
             "trade": j.trade(s.target, s.max_cost), "pareto": id(j) in front,
             "confirmed": j.candidate.label in confirmed, "runs": j.runs} for j in judged]


# ------------------------------------------------------------------------------------------ output
def figure_data(a: dict) -> dict[str, list]:
    """What the figure draws: per confirmed defence its cost and its loss at the target count, each the
    Hodges-Lehmann estimate with its interval, as the table prints them."""
    t = str(a["target"])
    keys = ("label", "origin", "cost", "cost_low", "cost_high", "loss", "loss_low", "loss_high")
    out: dict[str, list] = {k: [] for k in keys}
    for r in a["confirmed"]:
        for k, v in zip(keys, (r["label"], r["origin"], r["cost"]["hl"], r["cost"]["low"], r["cost"]["high"],
                               r["loss"][t]["hl"], r["loss"][t]["low"], r["loss"][t]["high"])):
            out[k].append(v)
    return out


def figure(a: dict):
    """The frontier: cost with no Byzantines against the confirmed worst-case loss at the target count,
    the declared margins as lines; the search phase's estimates of every candidate in grey behind."""
    import matplotlib  # only when a figure is drawn: matplotlib is slow to import

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = figure_data(a)
    t = str(a["target"])
    fig, (ax, growth) = plt.subplots(1, 2, figsize=(13, 5.5), gridspec_kw={"width_ratios": [3, 2]})
    search = [r for r in a["search"] if t in r["losses"]]
    ax.scatter([r["cost"] for r in search], [r["losses"][t] for r in search], s=12, color="0.75",
               label="every candidate (search seeds)")
    for k, lab in enumerate(d["label"]):
        x, y = d["cost"][k], d["loss"][k]
        if not (math.isfinite(x) and math.isfinite(y)):
            continue
        # floored at 0: an estimate can sit a rounding error outside an interval whose ends equal it
        xerr = [[max(0.0, x - d["cost_low"][k])], [max(0.0, d["cost_high"][k] - x)]]
        yerr = [[max(0.0, y - d["loss_low"][k])], [max(0.0, d["loss_high"][k] - y)]]
        existing = d["origin"][k] == "existing"
        ax.errorbar([x], [y], xerr=xerr, yerr=yerr, fmt="s" if existing else "o",
                    color="tab:red" if existing else "tab:blue", capsize=2, ms=5)
        ax.annotate(lab, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.axvline(a["max_cost"], ls="--", color="k", lw=0.8)
    ax.axhline(a["max_loss"], ls="--", color="k", lw=0.8)
    ax.set_xlabel("cost: items lost with no Byzantines, against the undefended swarm")
    ax.set_ylabel(f"worst-case loss found, {t} of {a['robots']} Byzantines")
    ax.xaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
    ax.yaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
    ax.set_title("confirmed: existing (squares), new (circles); 95 % Hodges-Lehmann intervals", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    _growth(growth, a, matplotlib)
    fig.tight_layout()
    return fig


def growth_data(a: dict) -> dict[str, dict[str, list[float]]]:
    """Per confirmed defence: Byzantine share, confirmed loss and its interval at each count (the table's
    numbers), and the floor kappa of the swarm at the same shares."""
    counts = [str(b) for b in a["byzantines"]]
    out = {r["label"]: {"share": [int(c) / a["robots"] for c in counts],
                        "loss": [r["loss"][c]["hl"] for c in counts],
                        "low": [r["loss"][c]["low"] for c in counts],
                        "high": [r["loss"][c]["high"] for c in counts]} for r in a["confirmed"]}
    out["floor"] = {"share": [int(c) / a["robots"] for c in counts],
                    "kappa": [math.inf if a["floor"][c] is None else a["floor"][c] for c in counts]}
    return out


def _growth(ax, a: dict, matplotlib) -> None:
    """The confirmed worst-case loss against the Byzantine share, per defence, with the swarm's floor
    kappa >= f / (n - 2f) on its own axis (a bound on any combination's error, not on items)."""
    g = growth_data(a)
    floor_ = g.pop("floor")
    for label, v in g.items():
        lo = [max(0.0, y - x) if math.isfinite(x) else 0.0 for y, x in zip(v["loss"], v["low"])]
        hi = [max(0.0, x - y) if math.isfinite(x) else 0.0 for y, x in zip(v["loss"], v["high"])]
        ax.errorbar(v["share"], v["loss"], yerr=[lo, hi], marker="o", ms=3, lw=1, capsize=2, label=label)
    ax.axhline(a["max_loss"], ls="--", color="k", lw=0.8)
    ax.set_xlabel("share of Byzantine robots")
    ax.set_ylabel("confirmed worst-case loss found")
    ax.xaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
    ax.yaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
    kappa = ax.twinx()
    kappa.plot(floor_["share"], floor_["kappa"], ls=":", color="0.3", marker="x", label="floor f/(n-2f), n = 25")
    kappa.set_ylabel("floor of robust aggregation, kappa", fontsize=8)
    kappa.legend(fontsize=7, loc="lower right")
    ax.legend(fontsize=6, loc="upper left", ncol=2)


def _pct(v: dict) -> str:
    if not math.isfinite(v.get("hl", math.nan)):
        return "undefined"
    return f"{v['hl']:.1%} {interval_text(v['low'], v['high'], '.1%')}"


def markdown(a: dict, *, reduced: str = "", wall_seconds: float | None = None, provenance: dict | None = None,
             records: list[str] | None = None, busy: dict | None = None) -> str:
    """The defence search's answers ``a`` as Markdown: each question answered from the confirmation seeds, then
    the search phase that chose the confirmed defences; a reduced run says so first."""
    t = str(a["target"])
    lines = ["# Defence search", ""]
    if reduced:
        lines += [f"**Reduced run** ({reduced}): not the declared study; its answers are not the study's.", ""]
    if provenance:
        lines += [f"Questions file: `{provenance.get('questions_file')}` at commit "
                  f"`{provenance.get('questions_commit')}`"
                  + (" (modified since)" if provenance.get("questions_modified") else "")
                  + f"; first run {provenance.get('first_run_utc')} UTC.", ""]
    b = a["bounded_defence"]
    lines += [f"**Is there a defence whose confirmed worst-case loss at {t} of {a['robots']} Byzantines is at "
              f"most {a['max_loss']:.0%}, at a cost of at most {a['max_cost']:.0%} with none? {b['answer']}**"
              + (f" ({', '.join(b['yes'])})" if b["yes"] else ""), ""]
    e = a["beats_existing"]
    if "new" in e:
        lines += [f"Best new trade `{e['new']}` against the best existing defence `{e['existing']}` at {t} "
                  f"Byzantines: loss difference {e['hl']:+.1%} {interval_text(e['low'], e['high'], '+.1%')}, p = "
                  f"{e['p']:.3g}, power {e['power']:.2f} at {-e['min_effect']:+.0%}: **{e['answer']}**.", ""]
    else:
        lines += [f"Best new against best existing: {e['answer']} ({e.get('note', '')}).", ""]
    counts = [str(b) for b in a["byzantines"]]
    lines += [f"Confirmed on {a['runs']} paired runs per defence and count (Hodges-Lehmann estimate [95 % "
              "interval]; loss to the worst attack the inner search found, against truthful Byzantines):", "",
              "| defence | family | cost, none | items lost per robot, none | "
              + " | ".join(f"loss, {c}" for c in counts) + f" | answer | floor of its voices, {t} | parameters |",
              "|---|---|---|---|" + "---|" * len(counts) + "---|---|---|"]
    for r in a["confirmed"]:
        vals = ", ".join(f"{k} {v:.4g}" for k, v in r["values"].items()) or "–"
        ci = r["cost_items"]
        items = (f"{ci['hl']:.2f} {interval_text(ci['low'], ci['high'], '.2f')}" if math.isfinite(ci["hl"])
                 else "undefined")
        lines.append(f"| {r['label']} | {r['family']} | {_pct(r['cost'])} | {items} | "
                     + " | ".join(_pct(r["loss"][c]) for c in counts)
                     + f" | {r['answer']} | {_voices(r['voices_floor'][t])} | {vals} |")
    lines += ["", "The floor of robust aggregation (Allouah et al. 2023), kappa >= f / (n - 2f): for the swarm "
              f"(n = {a['robots']} voices, f = the Byzantine count) "
              + ", ".join(f"{c}: {_kappa(a['floor'][c])}" for c in counts)
              + "; for a robust buyer's own voices (its `vectors` purchases and its own entry, the liars among "
              "them at the Byzantines' share of its neighbours) the table's column, every count in defence.json "
              "(`voices_floor`).  It bounds how close any combination of the vectors can stay to the honest "
              "ones, not the items lost.", "",
              "## Search phase (search seeds; what chose the confirmed defences)", "",
              "| candidate | origin | cost | " + " | ".join(f"loss, {c}" for c in counts)
              + " | trade | Pareto | confirmed |", "|---|---|---|" + "---|" * len(counts) + "---|---|---|"]
    for r in a["search"]:
        lines.append(f"| {r['label']} | {r['origin']} | {r['cost']:.1%} | "
                     + " | ".join(f"{r['losses'][c]:.1%}" if c in r["losses"] else "–" for c in counts)
                     + f" | {r['trade']:.3f} | {'yes' if r['pareto'] else ''} | {'yes' if r['confirmed'] else ''} |")
    if any(c not in r["losses"] for r in a["search"] for c in counts):
        lines += ["", "–: not judged at that count (the outer search judges every candidate at the target count; "
                  "the confirmed ones at every count, on the same search seeds)."]
    lines += ["", f"Runs: {a['made']} made in the confirmation now, {a['found']} found in the store"
              + (f"; {wall_seconds:.0f} s wall." if wall_seconds is not None else ".")]
    if busy:
        lines += ["", "## Cost", "", busy_markdown(busy).rstrip()]
    if records:
        lines += ["", *records]
    return "\n".join(lines) + "\n"


def _voices(v) -> str:
    """A robust buyer's own-voices floor; "–" for a defence that combines no vectors (NaN)."""
    return "–" if isinstance(v, float) and math.isnan(v) else _kappa(v)


def _kappa(v) -> str:
    return "none (half or more lie)" if v is None or not math.isfinite(v) else f"{v:.3f}"


def frames(result: Result) -> Report:
    """The confirmation runs as Parquet frames (``defence_cost.parquet``: label, run, items, undefended;
    ``defence_attacks.parquet``: label, byzantines, run, worst, reference), for DuckDB or pandas."""
    return Report([("defence_cost.parquet", result.cost_runs), ("defence_attacks.parquet", result.attack_runs)])


def write_frames(out: Path, result: Result) -> list[Path]:
    """``frames(result)`` written into ``out``; returns the files."""
    return frames(result).write(out)


def write(out: Path, a: dict, **meta) -> list[Path]:
    """``report(a, **meta)`` written into ``out``, each file whole or not at all; returns the files."""
    return report(a, **meta).write(out)


def report(a: dict, *, reduced: str = "", wall_seconds: float | None = None, provenance: dict | None = None,
           records: list[str] | None = None, busy: dict | None = None) -> Report:
    """``defence.json``, ``defence.md`` and ``frontier.png`` as a ``Report``; ``busy``: how busy the study
    kept its workers (``runner.feed.Busy.as_dict``)."""
    meta = {"reduced": reduced, "wall_seconds": wall_seconds, "provenance": provenance or {}, "busy": busy or {}}
    parts: list = [("defence.json", json.dumps(json_ready({**meta, **a}), indent=2) + "\n"),
                   ("defence.md", markdown(a, reduced=reduced, wall_seconds=wall_seconds, provenance=provenance,
                                           records=records, busy=busy))]
    if a["confirmed"]:
        parts.append(("frontier.png", drawn(lambda: figure(a), dpi=120)))
    return Report(parts)


class DefenceSearch(DeclaredStudy):
    """The defence search as a declared study: the search's ``result`` (the driver's, read from and made
    into the store) answered as its frames, ``defence.json``, ``defence.md`` and ``frontier.png``, with the
    store's record of the study's first run as its provenance; ``meta``: ``report``'s other arguments."""

    declaration = DECLARATION

    def __init__(self, study: Study, result: Result, **meta) -> None:
        self.study, self.result, self.meta = study, result, meta
        self.declaration = study.declaration  # the questions file the study was read from
        self.analysis: dict = {}

    def answer(self, store) -> Report:
        """The frames and the report of the result, ``store``'s record of the first run as provenance."""
        self.analysis = analyse(self.study, self.result)
        written = report(self.analysis, provenance=store.meta().get(NAME), **self.meta)
        return Report(frames(self.result).parts + written.parts)
