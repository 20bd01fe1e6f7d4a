"""Answers to the terrain questions (``terrain_questions.toml``, declared before the runs) from the
stores of the shipped experiments ``corridor``, ``two_food`` and ``crowd``, with a figure.

``infomarket terrain-report RESULTS --out DIR`` reads RESULTS/corridor, RESULTS/two_food and
RESULTS/crowd (``infomarket sweep NAME --out RESULTS/NAME``) and, when present,
the items per site stored with the two_food sweep (or a two_food_sites store), and writes DIR/terrain.md,
DIR/terrain.json and DIR/terrain.png.  Every test is on per-run values or on robots pooled over runs,
as the questions say; the answers are whatever the rules give, "no" included.

Each comparison also reports its run-level effect with a bootstrap interval and the power its
run count gives (``analysis.stats``); a rule its run count cannot decide answers "inconclusive".  Two-food
is tested at the run level (Wilcoxon signed-rank on per-run honest - Byzantine gaps), the robot-level
p-value reported beside it; the crowd's ratio is read from its bootstrap interval.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..cliargs import UsageError
from ..store.results import Store
from . import stats as st
from . import study
from .study import INCONCLUSIVE, NO, NOT_RUN, YES, by_power
from .declared import size_note
from .stats import mann_whitney

DECLARATION = study.packaged("terrain_questions.toml")
QUESTIONS = DECLARATION.path


def questions() -> dict:
    """The terrain study's declared questions by id."""
    return DECLARATION.questions


def _two_food_sites(root: Path) -> pd.DataFrame | None:
    """Items per site of the runs with two food sites: from the ``two_food`` sweep's store (sweeps store
    the sites table), else from a ``two_food_sites`` store (``infomarket run``); None without either."""
    for name in ("two_food", "two_food_sites"):
        store = Store(root / name)
        if not store.exists():
            continue
        sites = store.sites()
        if not len(sites):
            continue
        food = sites.groupby(["condition", "run"]).kind.transform(lambda k: int((k == "food").sum()))
        two = sites[food == 2]
        if len(two):  # one row per (run, site); runs of other conditions renamed apart
            return two.assign(run=two.condition.astype(str) + "/" + two.run.astype(str))
    return None


def _robots(root: Path, name: str, axis: str | None = None) -> pd.DataFrame:
    """The robots of the store ``root/name``, made by ``infomarket sweep name``: a store made by ``run``
    holds only the base condition, without the sweep's ``axis`` the question compares."""
    path = root / name
    store = Store(path)
    if not store.exists():
        raise UsageError(f"{path}: no results store; run `infomarket sweep {name} --out {path}` first")
    robots = store.robots()
    if axis is not None and axis not in robots.columns:
        raise UsageError(f"{path}: holds no runs of the sweep's {axis} conditions (`infomarket run` stores only "
                         f"the base condition); run `infomarket sweep {name} --out {path}`")
    return robots


def _ratio(a: float, b: float) -> float:
    return float("inf") if b == 0 else a / b


def _comparison_json(c: st.Comparison) -> dict:
    e = c.effect
    return {"test": c.test, "n": [c.n_x, c.n_y], "p": c.p, "min_p": c.min_p, "alpha": c.alpha,
            "hl_shift": e.hl, "hl_ci": [e.hl_low, e.hl_high], "cliffs_delta": e.delta,
            "cliffs_delta_ci": [e.delta_low, e.delta_high], "declared_shift": c.declared, "power": c.power}


def chain_blocked(robots: pd.DataFrame, rule: dict) -> dict:
    """Q1: per-run swarm items, market on vs off, behind the wall (and on the plane, descriptive).
    Power: to detect a doubling (a shift of (min_ratio - 1) x the market-off median) at p_below."""
    per_run = robots.groupby(["world", "market", "run"], observed=True).items_collected.sum()
    runs = {(w, m): per_run.loc[w, m].to_numpy() for w in ("corridor", "plane") for m in ("on", "off")}
    med = {k: float(np.median(v)) for k, v in runs.items()}
    on, off = runs["corridor", "on"], runs["corridor", "off"]
    test = st.compare(on, off, declared=(rule["min_ratio"] - 1.0) * med["corridor", "off"], alpha=rule["p_below"],
                      label="corridor: market on vs off")
    ratio = _ratio(med["corridor", "on"], med["corridor", "off"])
    yes = test.p < rule["p_below"] and ratio >= rule["min_ratio"]
    return {"answer": by_power(yes, test.power), "runs": len(on),
            "median_items": {f"{w}/{m}": med[w, m] for w, m in med},
            "iqr_items": {f"{w}/{m}": [float(np.percentile(v, 25)), float(np.percentile(v, 75))]
                          for (w, m), v in runs.items()},
            "p_corridor_on_gt_off": test.p, "ratio_corridor": ratio,
            "ratio_corridor_ci": list(_ci(st.median_ratio(on, off))), "test": _comparison_json(test),
            "describe": test.describe(" items"),
            "ratio_plane": _ratio(med["plane", "on"], med["plane", "off"]),
            "corridor_share_of_plane": _ratio(med["corridor", "on"], med["plane", "on"]),
            "per_run": {f"{w}/{m}": v.tolist() for (w, m), v in runs.items()}}


def _ci(r: st.Ratio) -> tuple[float, float]:
    return r.low, r.high


def waypoints_restore(naive: pd.DataFrame, waypoint: pd.DataFrame, rule: dict) -> dict:
    """Q2: per-run swarm items of waypoint robots behind the wall vs the naive vector market behind the
    same wall (a) and vs the vector market on the open plane (b), as declared."""
    def runs(robots, world):
        sub = robots[(robots.world == world) & (robots.market == "on")]
        return sub.groupby("run", observed=True).items_collected.sum().to_numpy()

    way, vec, plane = runs(waypoint, "corridor"), runs(naive, "corridor"), runs(naive, "plane")
    way_plane = runs(waypoint, "plane")
    med = {k: float(np.median(v)) for k, v in (("waypoint/corridor", way), ("vector/corridor", vec),
                                               ("vector/plane", plane), ("waypoint/plane", way_plane))}
    test = st.compare(way, vec, declared=(rule["min_ratio"] - 1.0) * med["vector/corridor"], alpha=rule["p_below"],
                      label="behind the wall: waypoints vs vector market")
    ratio = _ratio(med["waypoint/corridor"], med["vector/corridor"])
    share = st.median_ratio(way, plane)
    a = test.p < rule["p_below"] and ratio >= rule["min_ratio"]
    b = share.value >= rule["min_share_of_plane"]

    def two(x, y):
        return float(sps.mannwhitneyu(x, y, alternative="two-sided").pvalue)

    answer = (YES if b else "partly") if a else by_power(False, test.power)
    return {"answer": answer, "beats_vector_market": bool(a),
            "keeps_half_of_plane": bool(b), "runs": len(way),
            "median_items": med,
            "iqr_items": {k: [float(np.percentile(v, 25)), float(np.percentile(v, 75))]
                          for k, v in (("waypoint/corridor", way), ("vector/corridor", vec),
                                       ("vector/plane", plane), ("waypoint/plane", way_plane))},
            "p_waypoint_gt_vector_corridor": test.p, "ratio_to_vector_corridor": ratio,
            "test": _comparison_json(test), "describe": test.describe(" items"),
            "share_of_plane": share.value, "share_of_plane_ci": list(_ci(share)),
            "p_waypoint_corridor_vs_plane": two(way, plane),
            "p_waypoint_vs_vector_plane": two(way_plane, plane),
            "per_run": {"waypoint/corridor": way.tolist(), "waypoint/plane": way_plane.tolist()}}


def _separation(sub: pd.DataFrame, alpha: float) -> dict:
    honest = sub[sub.honest].wealth_share.to_numpy()
    byz = sub[~sub.honest].wealth_share.to_numpy()
    robot_level = mann_whitney(honest, byz)
    means = sub.groupby(["run", "honest"]).wealth_share.mean().unstack()
    gap = (means[True] - means[False]).to_numpy()
    run_level = st.paired(100 * gap, alpha=alpha)
    return {"median_honest_pct": 100 * float(np.median(honest)), "median_byzantine_pct": 100 * float(np.median(byz)),
            "p_run_level": run_level.p, "min_p_run_level": run_level.min_p,
            "gap_hl_pct": run_level.hl, "gap_hl_ci_pct": [run_level.hl_low, run_level.hl_high],
            "describe": run_level.describe(" points"),
            "p_robot_level": robot_level.pvalue, "runs": len(gap), "runs_separated": float((gap > 0).mean()),
            "median_gap_pct": 100 * float(np.median(gap)), "gaps": gap}


def outlier_two_food(robots: pd.DataFrame, rule: dict, sites: pd.DataFrame | None) -> dict:
    """Q3: honest vs Byzantine wealth share with two food sites (and with one, descriptive).  The test is
    run-level: each run's honest-minus-Byzantine mean share, Wilcoxon signed-rank; the
    robot-level Mann-Whitney of the original rule pools robots over runs and is reported beside it."""
    two = _separation(robots[robots.food_sites == 2], rule["p_below"])
    one = _separation(robots[robots.food_sites == 1], rule["p_below"])
    yes = (two["median_honest_pct"] > two["median_byzantine_pct"] and two["p_run_level"] < rule["p_below"]
           and two["runs_separated"] >= rule["min_runs_separated"])
    reachable = two["min_p_run_level"] < rule["p_below"]
    gaps = sps.mannwhitneyu(two["gaps"], one["gaps"], alternative="two-sided").pvalue
    out = {"answer": YES if yes else (NO if reachable else INCONCLUSIVE),
           "two_sites": {k: v for k, v in two.items() if k != "gaps"},
           "one_site": {k: v for k, v in one.items() if k != "gaps"}, "p_gaps_differ": float(gaps),
           "gaps_pct": {"two": (100 * two["gaps"]).tolist(), "one": (100 * one["gaps"]).tolist()}}
    if sites is not None and len(sites):
        food = sites[sites.kind == "food"].pivot(index="run", columns="site", values="items")
        total = food.sum(axis=1).replace(0, np.nan)
        near = food.iloc[:, 1] / total
        out["near_site_share"] = {"median": float(near.median()), "q25": float(near.quantile(0.25)),
                                  "q75": float(near.quantile(0.75)), "runs": int(near.notna().sum())}
    return out


def crowd_collisions(robots: pd.DataFrame, rule: dict) -> dict:
    """Q4: per-robot items per run with collisions on vs off, 100 robots (25, descriptive).  The answer
    reads the bootstrap interval of the ratio of medians: yes when it lies at or above
    min_ratio, no when below, inconclusive when it straddles."""
    per_run = robots.groupby(["robots", "collisions", "run"], observed=True).items_collected.mean()
    out = {}
    for n in (100, 25):
        on, off = per_run.loc[n, True].to_numpy(), per_run.loc[n, False].to_numpy()
        p = float(sps.mannwhitneyu(on, off, alternative="two-sided").pvalue)
        r = st.median_ratio(on, off)
        e = st.effect(on, off)
        out[n] = {"median_on": float(np.median(on)), "median_off": float(np.median(off)),
                  "ratio": r.value, "ratio_ci": [r.low, r.high], "hl_shift": e.hl, "hl_ci": [e.hl_low, e.hl_high],
                  "cliffs_delta": e.delta, "cliffs_delta_ci": [e.delta_low, e.delta_high], "p_two_sided": p,
                  "runs": len(on), "per_run_on": on.tolist(), "per_run_off": off.tolist()}
    out["answer"] = st.answer_interval(st.Ratio(out[100]["ratio"], *out[100]["ratio_ci"], st.CONFIDENCE),
                                       rule["min_ratio"])
    return out


def _boxes(ax, data: list, labels: list[str], positions=None) -> None:
    """Box plots in the report's convention (``boxplots.draw_boxes``), each tick naming its run count."""
    from .boxplots import HONEST, draw_boxes  # matplotlib loads when drawing, not when the CLI starts

    pos = list(range(1, len(data) + 1)) if positions is None else list(positions)
    draw_boxes(ax, [np.asarray(d, float) for d in data], pos, HONEST, width=0.55)
    ax.set_xticks(pos, [f"{lab}\nn = {len(d)}" for lab, d in zip(labels, data)], fontsize=7)
    ax.set_xlim(min(pos) - 0.6, max(pos) + 0.6)


def terrain_figure(a: dict):
    """The terrain answers' figure (a ``matplotlib.figure.Figure``): one panel per question, every box
    labelled with its run count, reference lines named in a legend."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure(figsize=(15, 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1.35, 0.8, 1.2]})
    q1 = a["chain_blocked"]["per_run"]
    keys = ["plane/on", "plane/off", "corridor/on", "corridor/off"]
    data = [q1[k] for k in keys]
    labels = ["plane\nmarket", "plane\nno market", "corridor\nmarket", "corridor\nno market"]
    w = a["waypoints_restore"]
    if w["answer"] != NOT_RUN:
        data += [w["per_run"]["waypoint/plane"], w["per_run"]["waypoint/corridor"]]
        labels += ["plane\nwaypoints", "corridor\nwaypoints"]
    _boxes(ax[0], data, labels)
    # items per run span 0 to several hundred: linear up to 10, logarithmic above, never below 0
    ax[0].set_yscale("symlog", linthresh=10, linscale=0.6)
    upper = max([20.0] + [1.5 * float(np.max(d)) for d in data if len(d)])
    ticks = [t for t in (0, 5, 10, 100, 1000, 10000) if t <= upper]
    ax[0].set_ylim(0, upper)
    ax[0].set_yticks(ticks, [f"{t:g}" for t in ticks])
    ax[0].set_ylabel("items per run (whole swarm)")
    robots = "25 naive" + (" / 25 waypoint" if w["answer"] != NOT_RUN else "")
    ax[0].set_title(f"corridor: {robots} robots\n(symlog axis: linear below 10)", loc="left", fontsize=9)
    q3 = a["outlier_two_food"]["gaps_pct"]
    _boxes(ax[1], [q3["one"], q3["two"]], ["one food site", "two food sites"])
    ax[1].axhline(0, color="grey", linestyle="--", linewidth=0.9)
    ax[1].set_ylabel("honest − Byzantine mean wealth share\nper run (percentage points)")
    ax[1].set_title("two_food: 20 sceptical + 5 scaboteurs,\nstaking", loc="left", fontsize=9)
    q4 = a["crowd_collisions"]
    data = [q4[str(n) if str(n) in q4 else n][k] for n in (25, 100) for k in ("per_run_off", "per_run_on")]
    labels = ["25\nno coll.", "25\ncollisions", "100\nno coll.", "100\ncollisions"]
    if "crowd_sensing" in a:  # exploratory: robots sense each other
        e = a["crowd_sensing"]
        data += [e[str(n) if str(n) in e else n]["per_run_on"] for n in (25, 100)]
        labels += ["25 coll.\n+sensing*", "100 coll.\n+sensing*"]
    _boxes(ax[2], data, labels)
    ax[2].set_ylim(bottom=0)
    ax[2].set_ylabel("items per robot per run")
    ax[2].set_title("crowd: naive robots that collide" + (" (* exploratory)" if "crowd_sensing" in a else ""),
                    loc="left", fontsize=9)
    fig.legend(handles=[Line2D([], [], color="grey", linestyle="--", label="no gap (0 points)")],
               loc="outside lower center", frameon=False, fontsize=8)
    fig.suptitle("Terrain questions: per-run values; n = runs per box", fontsize=10)
    return fig


def figure(a: dict, path: Path) -> Path:
    """Draw the terrain study's figure from the answers ``a`` and save it (PNG, no timestamp) at ``path``."""
    terrain_figure(a).savefig(path, dpi=110, metadata={"Software": None})
    return path


def _declarations(root: Path, names) -> list[str]:
    """Per store: were the terrain questions declared before its first run (analysis.declared)?"""
    out = []
    for name in names:
        if (root / name).exists():
            out.append(f"store {name}: " + DECLARATION.lock_summary(Store(root / name).declarations(), "questions."))
    return out


def answer(root: Path) -> dict:
    """Answer each terrain question from the stores under ``root`` (one folder per experiment); a question whose
    store is absent is answered 'not run'."""
    q = questions()
    sites = _two_food_sites(root)
    return {"chain_blocked": chain_blocked(_robots(root, "corridor", "world"), q["chain_blocked"]),
            "waypoints_restore": (waypoints_restore(_robots(root, "corridor", "world"),
                                                    _robots(root, "corridor_waypoints", "world"),
                                                    q["waypoints_restore"])
                                  if (root / "corridor_waypoints").exists() else
                                  {"answer": NOT_RUN, "why": "no corridor_waypoints store"}),
            "outlier_two_food": outlier_two_food(_robots(root, "two_food", "food_sites"), q["outlier_two_food"], sites),
            "crowd_collisions": crowd_collisions(_robots(root, "crowd", "collisions"), q["crowd_collisions"]),
            **({"crowd_sensing": exploratory(crowd_collisions(_robots(root, "crowd_sensing", "collisions"),
                                                              q["crowd_collisions"]))}
               if (root / "crowd_sensing").exists() else {}),
            "declarations": _declarations(root, ("corridor", "corridor_waypoints", "two_food", "crowd"))}


def exploratory(a: dict) -> dict:
    """Statistics of a condition added after the declared answers: reported, but no rule decides it."""
    a.pop("answer", None)
    a["exploratory"] = True
    return a


def _waypoint_line(q: dict, w: dict) -> str:
    head = f"2. **{q['waypoints_restore']['question']}** — "
    if w["answer"] == NOT_RUN:
        return head + "**not run**: no `corridor_waypoints` store (`infomarket sweep corridor_waypoints`)."
    m, r = w["median_items"], q["waypoints_restore"]
    return (head + f"**{w['answer']}**.  Median items per run ({w['runs']} runs each, market on): waypoint robots "
            f"behind the wall {m['waypoint/corridor']:g} vs the vector market behind the same wall "
            f"{m['vector/corridor']:g} (ratio {w['ratio_to_vector_corridor']:.2f}; {w['describe']}; needed p < "
            f"{r['p_below']:g} and ratio ≥ {r['min_ratio']:g}: "
            f"{'met' if w['beats_vector_market'] else 'not met'}); the open plane with the vector market "
            f"{m['vector/plane']:g}, so waypoints keep {100 * w['share_of_plane']:.0f} % of it (95 % interval "
            f"{100 * w['share_of_plane_ci'][0]:.0f}–{100 * w['share_of_plane_ci'][1]:.0f} %; needed ≥ "
            f"{100 * r['min_share_of_plane']:.0f} %: {'met' if w['keeps_half_of_plane'] else 'not met'}; two-sided p = "
            f"{_p(w['p_waypoint_corridor_vs_plane'])}).  Descriptive: waypoint robots on the open plane "
            f"{m['waypoint/plane']:g} (vs naive {m['vector/plane']:g}, two-sided p = "
            f"{_p(w['p_waypoint_vs_vector_plane'])}).")


def _p(p: float) -> str:
    return f"{p:.1e}" if p < 0.001 else f"{p:.3f}"


def _ci_txt(ci) -> str:
    return f"[{ci[0]:.3g}, {ci[1]:.3g}]"


def markdown(a: dict) -> str:
    """The answers as ``terrain.md``: each question, its answer and the numbers it rests on."""
    q = questions()
    c, t, k = a["chain_blocked"], a["outlier_two_food"], a["crowd_collisions"]
    m = c["median_items"]
    lines = [
        f"1. **{q['chain_blocked']['question']}** — **{c['answer']}**.  Median items per run "
        f"({c['runs']} runs each): corridor with market {m['corridor/on']:g}, without {m['corridor/off']:g} "
        f"(ratio {c['ratio_corridor']:.2f} {_ci_txt(c['ratio_corridor_ci'])}; {c['describe']}); "
        f"plane with market {m['plane/on']:g}, without {m['plane/off']:g} (ratio {c['ratio_plane']:.1f}).  "
        f"Behind the wall the market keeps {100 * c['corridor_share_of_plane']:.0f} % of the plane's throughput.",
        _waypoint_line(q, a["waypoints_restore"]),
    ]
    two, one = t["two_sites"], t["one_site"]
    text = (f"3. **{q['outlier_two_food']['question']}** — **{t['answer']}**.  Two food sites: median wealth "
            f"share honest {two['median_honest_pct']:.2f} % vs Byzantine {two['median_byzantine_pct']:.2f} %; "
            f"per-run honest − Byzantine mean share: {two['describe']} (robot-level, robots pooled over runs as "
            f"the paper does: one-sided Mann–Whitney p = {_p(two['p_robot_level'])}).  One food site: "
            f"{one['median_honest_pct']:.2f} % vs {one['median_byzantine_pct']:.2f} %; {one['describe']} "
            f"(robot-level p = {_p(one['p_robot_level'])}); per-run gaps, two sites vs one: two-sided "
            f"Mann–Whitney p = {_p(t['p_gaps_differ'])}.")
    if "near_site_share" in t:
        s = t["near_site_share"]
        text += (f"  Share of food items picked at the near site: median {100 * s['median']:.0f} % "
                 f"(IQR {100 * s['q25']:.0f}–{100 * s['q75']:.0f} %, {s['runs']} runs of `infomarket run two_food`).")
    lines.append(text)
    lines.append(
        f"4. **{q['crowd_collisions']['question']}** — **{k['answer']}**.  100 robots: median items per robot "
        f"per run {k[100]['median_on']:.2f} with collisions vs {k[100]['median_off']:.2f} without (ratio "
        f"{k[100]['ratio']:.2f}, 95 % bootstrap interval {_ci_txt(k[100]['ratio_ci'])}; HL shift "
        f"{k[100]['hl_shift']:+.3g} {_ci_txt(k[100]['hl_ci'])}, Cliff's delta {k[100]['cliffs_delta']:+.2f} "
        f"{_ci_txt(k[100]['cliffs_delta_ci'])}; two-sided Mann–Whitney p = {_p(k[100]['p_two_sided'])}, "
        f"{k[100]['runs']} runs each); 25 robots: {k[25]['median_on']:.2f} vs {k[25]['median_off']:.2f} (ratio "
        f"{k[25]['ratio']:.2f} {_ci_txt(k[25]['ratio_ci'])}, p = {_p(k[25]['p_two_sided'])}).")
    if "crowd_sensing" in a:
        e = a["crowd_sensing"]
        lines.append(
            "5. *Exploratory, added after answer 4 (no rule declared):* with `robot.sense_robots` (robots "
            f"reflect off each other), 100 robots: {e[100]['median_on']:.2f} items per robot per run with "
            f"collisions vs {e[100]['median_off']:.2f} without (ratio {e[100]['ratio']:.2f}, p = "
            f"{_p(e[100]['p_two_sided'])}); 25 robots: {e[25]['median_on']:.2f} vs {e[25]['median_off']:.2f} "
            f"(ratio {e[25]['ratio']:.2f}, p = {_p(e[25]['p_two_sided'])}).")
    notes = []
    for qid, key in (("chain_blocked", "runs"), ("waypoints_restore", "runs"), ("outlier_two_food", None),
                     ("crowd_collisions", None)):
        ans = a[qid]
        if ans.get("answer") == NOT_RUN:
            runs = None
        elif key:
            runs = ans.get(key)
        else:
            runs = ans["two_sites"]["runs"] if qid == "outlier_two_food" else ans[100]["runs"]
        note = size_note(q[qid].get("runs"), [runs] if runs else [])
        if note:
            notes.append(f"{qid}: {note}")
    if notes:
        lines.append("")
        lines += [f"- NOTE: {n}." for n in notes]
    if "declarations" in a:
        lines.append("")
        lines += [f"- {line}" for line in a["declarations"]]
    lines += ["", *DECLARATION.record_markdown()]
    return "\n".join(lines) + "\n"


def jsonable(a):
    """``a`` (the answers) with numpy numbers as Python ones and keys as strings, for ``json.dumps``."""
    if isinstance(a, dict):
        return {str(k): jsonable(v) for k, v in a.items()}
    if isinstance(a, (list, tuple)):
        return [jsonable(v) for v in a]
    if isinstance(a, (np.floating, np.integer)):
        return a.item()
    return a


class TerrainStudy(study.Study):
    """The terrain study: its questions (``terrain_questions.toml``) answered from a folder holding its
    stores, as ``terrain.md``, ``terrain.json`` and ``terrain.png``."""

    declaration = DECLARATION

    def answer(self, store) -> study.Report:
        """The answers from the folder ``store`` (its stores corridor/, two_food/, crowd/, ...)."""
        a = answer(Path(store))
        return study.Report.of("terrain", markdown(a), extra=[("terrain.json", json.dumps(jsonable(a), indent=1))],
                               figure=lambda p: figure(a, p))
