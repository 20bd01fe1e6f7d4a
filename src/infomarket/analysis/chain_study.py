"""Answers to the chain study's questions (``chain_questions.toml``, declared before the runs): does the
paper's result (Figs. 3-4: the Byzantines' wealth share stays low; Fig. 7: staking helps the swarm
against 3 Byzantines above Theta) hold when the robots run the ledger themselves (docs/chain-model.md),
at toychain's and geth-argos's settings, and at what block period, loss rate or gas price does it break?

``infomarket chain-study STORE [STORE ...] --out DIR`` (``analysis.chain_cli``; figure: ``analysis.chain_figure``)
reads the stores of the shipped experiments
``chain_paper``, ``chain_fig7``, ``chain_sweep``, ``chain_fig7_sweep`` (and ``chain_partition`` once
``chain.partition`` exists), made with ``infomarket sweep NAME --out STORE``, and writes DIR/chain-study.md,
DIR/chain-study.csv (question, rule, n, effect with its 95 % interval, answer) and DIR/chain-study.png.
Every comparison is run-level, through ``analysis.stats`` (Mann-Whitney with Holm, Hodges-Lehmann and
Cliff's delta with bootstrap intervals, simulated power); a rule its runs cannot decide answers
"inconclusive", a question whose runs are absent "not run" (or "pending" for the partition).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import stats as st
from .study import NOT_RUN, PENDING, Verdict, packaged

DECLARATION = packaged("chain_questions.toml")
QUESTIONS = DECLARATION.path
YES, NO, INCONCLUSIVE = st.YES, st.NO, st.INCONCLUSIVE
PAPER, FIG7, SWEEP, FIG7_SWEEP, PARTITION = ("chain_paper", "chain_fig7", "chain_sweep", "chain_fig7_sweep",
                                             "chain_partition")
#: the sweeps' setting label of each axis value; the axis's toychain value is toychain's own runs
AXES = {"period": ("period_{}", 150), "loss": ("loss_{}", 0.0), "gas": ("gas_{}", 0.0)}


def declaration() -> dict:
    """The chain study's declared questions, rules and margins (``chain_questions.toml``) as parsed TOML."""
    return DECLARATION.data


# ------------------------------------------------------------------------------------------ per run
def per_run(robots: pd.DataFrame) -> pd.DataFrame:
    """One row per run: its experiment, condition keys and ``byz_share`` (the Byzantines' total wealth
    share, %), ``gap`` (honest minus Byzantine mean wealth share, percentage points) and ``items`` (the
    swarm's items after the transitory period)."""
    if robots.empty:
        return pd.DataFrame(columns=["experiment", "condition", "run", "byz_share", "gap", "items"])
    keys = [k for k in ("chain", "payment", "byzantines", "market", "rotation_angle", "partition", "base")
            if k in robots.columns]
    r = robots.assign(_byz=np.where(robots["honest"], 0.0, robots["wealth_share"]),
                      _hon=np.where(robots["honest"], robots["wealth_share"], np.nan),
                      _byzm=np.where(robots["honest"], np.nan, robots["wealth_share"]))
    g = r.groupby(["experiment", "condition", "run"], observed=True, dropna=False)
    out = pd.DataFrame({"byz_share": 100.0 * g["_byz"].sum(), "items": g["items_collected"].sum(),
                        "gap": 100.0 * (g["_hon"].mean() - g["_byzm"].mean())})
    for k in keys:
        out[k] = g[k].first()
    return out.reset_index()


def _sel(runs: pd.DataFrame, experiment: str, col: str = "byz_share", **keys) -> np.ndarray:
    sel = runs[runs["experiment"] == experiment] if "experiment" in runs.columns else runs.iloc[0:0]
    for k, v in keys.items():
        if k not in sel.columns:
            return np.array([])
        sel = sel[np.isclose(sel[k].astype(float), float(v))] if isinstance(v, float) else sel[sel[k] == v]
    return sel[col].to_numpy(float)


# ------------------------------------------------------------------------------------------ verdicts
def _ci(c: st.Comparison, unit: str) -> str:
    e = c.effect
    return (f"HL {e.hl:+.3g}{unit} [{e.hl_low:.3g}, {e.hl_high:.3g}], "
            f"Cliff's delta {e.delta:+.2f} [{e.delta_low:.2f}, {e.delta_high:.2f}]")


def wealth_verdict(pairs: list[tuple[str, np.ndarray, np.ndarray, float]], alpha: float = st.ALPHA,
                   target: float = st.POWER) -> Verdict:
    """The wealth rule over ``pairs`` (label, chain runs, instant runs, margin m in pp): per pair, holds
    when H1 chain < instant + m, breaks when H1 chain > instant + m (each Holm-adjusted over the pairs);
    yes when all hold, no when any breaks, else inconclusive ("n too small" when an undecided pair's power
    to show non-inferiority at a true shift 0 is below ``target``)."""
    declared = len(pairs)
    pairs = [p for p in pairs if len(p[1]) and len(p[2])]
    if not pairs:
        return Verdict(NOT_RUN)
    k = len(pairs)
    ni = st.adjust([st.compare(x, y, alternative="less", shift=-m, declared=0.0, family=k, alpha=alpha,
                               label=f"{lab}: chain < instant + {m:g} pp") for lab, x, y, m in pairs])
    br = st.adjust([st.compare(x, y, alternative="greater", shift=-m, alpha=alpha,
                               label=f"{lab}: chain > instant + {m:g} pp") for lab, x, y, m in pairs])
    holds = [c.significant for c in ni]
    breaks = [c.significant for c in br]
    details, weak = [], False
    for (lab, x, y, m), a, b, h, bk in zip(pairs, ni, br, holds, breaks):
        tost_p = st.tost(x, y, m, alpha=alpha)[0]
        state = "holds" if h else "BREAKS" if bk else "undecided"
        if not h and not bk and a.power < target:
            weak = True
        details.append(f"{lab}: {state}; byz share medians {a.median_x:.3g} % vs {a.median_y:.3g} % (n = {a.n_x}, "
                       f"{a.n_y}), {_ci(a, ' pp')}; non-inferiority within {m:g} pp p_Holm = {st._fmt_p(a.p_adjusted)} "
                       f"(power {a.power:.2f}), beyond-margin p_Holm = {st._fmt_p(b.p_adjusted)}, "
                       f"TOST p = {st._fmt_p(tost_p)}")
    if all(holds):
        ans = YES
    elif any(breaks):
        ans = NO
    else:
        ans = INCONCLUSIVE
    worst = max(range(k), key=lambda i: ni[i].effect.hl)
    n = ", ".join(sorted({f"{c.n_x} vs {c.n_y}" for c in ni}))
    note = st.N_TOO_SMALL if ans == INCONCLUSIVE and weak else ""
    if k < declared:
        note = ", ".join(x for x in (note, f"{k} of {declared} conditions run") if x)
    return Verdict(ans, n=n, effect=f"largest shift ({pairs[worst][0]}): {_ci(ni[worst], ' pp')}", details=details,
                   note=note)


def fig7_verdict(angles: list[tuple[str, np.ndarray, np.ndarray, float]], alpha: float = st.ALPHA,
                 target: float = st.POWER) -> Verdict:
    """The Fig. 7 rule over ``angles`` (label, staking runs, delayed runs, d): helps when H1 staking >
    delayed, shown not to help when H1 staking < delayed + d (each Holm-adjusted over the angles);
    stats.answer(yes = helps at all, no = shown not to help at one or more)."""
    angles = [a for a in angles if len(a[1]) and len(a[2]) and not math.isnan(a[3])]
    if not angles:
        return Verdict(NOT_RUN)
    k = len(angles)
    helps = st.adjust([st.compare(x, y, alternative="greater", declared=d, family=k, alpha=alpha,
                                  label=f"{lab}: staking > no staking") for lab, x, y, d in angles])
    not_d = st.adjust([st.compare(x, y, alternative="less", shift=-d, alpha=alpha,
                                  label=f"{lab}: staking < no staking + {d:.3g}") for lab, x, y, d in angles])
    yes = all(c.significant for c in helps)
    no = any(c.significant for c in not_d)
    ans = st.answer(yes, no)
    details, weak = [], False
    for (lab, _x, _y, d), h, nd in zip(angles, helps, not_d):
        state = "helps" if h.significant else "does NOT help" if nd.significant else "undecided"
        if not h.significant and not nd.significant and h.power < target:
            weak = True
        details.append(f"{lab}: {state}; items medians staking {h.median_x:.4g} vs no staking {h.median_y:.4g} "
                       f"(n = {h.n_x}, {h.n_y}), gain {_ci(h, '')}; p_Holm(gain > 0) = {st._fmt_p(h.p_adjusted)} "
                       f"(power {h.power:.2f} for a gain of {d:.3g}), "
                       f"p_Holm(gain < {d:.3g}) = {st._fmt_p(nd.p_adjusted)}")
    least = min(range(k), key=lambda i: helps[i].effect.hl)
    n = ", ".join(sorted({f"{c.n_x} vs {c.n_y}" for c in helps}))
    note = st.N_TOO_SMALL if ans == INCONCLUSIVE and weak else ""
    return Verdict(ans, n=n, effect=f"smallest gain ({angles[least][0]}): {_ci(helps[least], ' items')}",
                   details=details, note=note)


# ------------------------------------------------------------------------------------------ questions
def _margin(decl: dict, k: int) -> float:
    return float(decl["study"]["byzantine_margin_per_robot"]) * k


def _d(runs: pd.DataFrame, decl: dict, angle: float) -> float:
    ref = _sel(runs, FIG7, "items", chain="instant", market="no_staking", rotation_angle=angle)
    return float(decl["study"]["fig7_gain_share"]) * float(np.median(ref)) if len(ref) else math.nan


def wealth_question(runs: pd.DataFrame, decl: dict, setting: str) -> Verdict:
    """Does the paper's wealth result hold on the chain ``setting`` as on the instant ledger?

    Pairs each of Figs. 3 and 4's conditions (1, 3 and 5 Byzantines) on the chain with the same condition on
    the instant ledger and judges them by the declared margin; the honest-minus-Byzantine gaps on the chain
    are added as descriptive details.

    Args:
        runs: one row per run (``per_run``).
        decl: the declaration (``declaration()``).
        setting: the chain setting's name, as the runs' ``chain`` column writes it.
    """
    pairs = []
    for payment in ("outlier", "staking"):
        for k in (1, 3, 5):
            x = _sel(runs, PAPER, chain=setting, payment=payment, byzantines=k)
            y = _sel(runs, PAPER, chain="instant", payment=payment, byzantines=k)
            fig = "3" if payment == "outlier" else "4"
            pairs.append((f"Fig. {fig}{'ABC'[(k - 1) // 2]} ({k} Byz.)", x, y, _margin(decl, k)))
    v = wealth_verdict(pairs, decl["study"]["alpha"], decl["study"]["power_target"])
    for payment in ("outlier", "staking"):  # the paper's own claim on the chain (descriptive, declared)
        for k in (1, 3, 5):
            gap = (_sel(runs, PAPER, "gap", chain=setting, payment=payment, byzantines=k)
                   if "gap" in runs.columns else [])
            if len(gap) and not np.isnan(gap).all():
                fig = "3" if payment == "outlier" else "4"
                v.details.append(f"(descriptive) Fig. {fig}{'ABC'[(k - 1) // 2]} on {setting}, honest minus Byzantine "
                                 f"mean share: {st.paired(gap).describe(' pp')}")
    return v


def fig7_question(runs: pd.DataFrame, decl: dict, setting: str, angles=(45.0, 90.0)) -> Verdict:
    """Does staking still raise the swarm's items on the chain ``setting`` (Fig. 7) at each of ``angles``?

    Compares staking with no staking on the chain at each rotation angle; staking on the chain against
    staking on the instant ledger is added as descriptive details.
    """
    rows = [(f"{a:g} deg", _sel(runs, FIG7, "items", chain=setting, market="staking", rotation_angle=a),
             _sel(runs, FIG7, "items", chain=setting, market="no_staking", rotation_angle=a), _d(runs, decl, a))
            for a in angles]
    v = fig7_verdict(rows, decl["study"]["alpha"], decl["study"]["power_target"])
    for a in angles:  # descriptive (declared): staking on the chain vs staking on the instant ledger
        x = _sel(runs, FIG7, "items", chain=setting, market="staking", rotation_angle=a)
        y = _sel(runs, FIG7, "items", chain="instant", market="staking", rotation_angle=a)
        if len(x) and len(y):
            e = st.effect(x, y)
            v.details.append(f"(descriptive) {a:g} deg, staking on {setting} vs on the instant ledger: medians "
                             f"{np.median(x):.4g} vs {np.median(y):.4g}, "
                             f"HL {e.hl:+.3g} items [{e.hl_low:.3g}, {e.hl_high:.3g}]")
    return v


def axis_values(decl: dict, axis: str) -> list[tuple[float, str]]:
    """(value, setting label) along an axis, in the declared order; the toychain value's label is
    "toychain".  The gas axis's labels are the amended ones (``[amendment_gas]``: the conditions rerun
    with the cold gas table) when the declaration has them."""
    s = decl["study"]
    values = s["period"] if axis == "period" else s["loss"] if axis == "loss" else s["gas_ratio"]
    fmt, base = AXES[axis]
    if axis == "gas" and "amendment_gas" in decl:  # the gas conditions rerun with the cold gas table
        values, fmt = decl["amendment_gas"]["gas_ratio"], decl["amendment_gas"]["label"]
    out = []
    for v in values:
        if float(v) == float(base):
            out.append((v, "toychain"))
        else:
            out.append((v, fmt.format(int(v) if axis == "period" else f"{v:g}")))
    return out


def axis_point(runs: pd.DataFrame, decl: dict, label: str) -> tuple[str, Verdict, Verdict]:
    """The verdict at one setting of a sweep: (holds / breaks / inconclusive / not run, wealth, Fig. 7)."""
    paper = label == "toychain"
    pairs = []
    for payment in ("outlier", "staking"):
        x = _sel(runs, PAPER if paper else SWEEP, chain=label, payment=payment, **({"byzantines": 5} if paper else {}))
        y = _sel(runs, PAPER, chain="instant", payment=payment, byzantines=5)
        pairs.append((f"Fig. {'3C' if payment == 'outlier' else '4C'}", x, y, _margin(decl, 5)))
    w = wealth_verdict(pairs, decl["study"]["alpha"], decl["study"]["power_target"])
    exp, extra = (FIG7, {"rotation_angle": 90.0}) if paper else (FIG7_SWEEP, {})
    f = fig7_verdict([("90 deg", _sel(runs, exp, "items", chain=label, market="staking", **extra),
                       _sel(runs, exp, "items", chain=label, market="no_staking", **extra), _d(runs, decl, 90.0))],
                     decl["study"]["alpha"], decl["study"]["power_target"])
    answers = [v.answer for v in (w, f) if v.answer != NOT_RUN]
    if not answers:
        state = NOT_RUN
    elif NO in answers:
        state = "breaks"
    elif all(a == YES for a in answers) and len(answers) == 2:
        state = "holds"
    elif all(a == YES for a in answers):
        state = "holds (wealth only)" if f.answer == NOT_RUN else "holds (Fig. 7 only)"
    else:
        state = INCONCLUSIVE
    return state, w, f


def breaks_question(runs: pd.DataFrame, decl: dict, axis: str) -> Verdict:
    """Smallest value of the axis at which the result breaks: yes (at it), no (holds at every value),
    inconclusive (breaks nowhere, undecided somewhere), not run."""
    states, details = [], []
    for v, label in axis_values(decl, axis):
        state, w, f = axis_point(runs, decl, label)
        states.append((v, state, w, f))
        details.append(f"{axis} {v:g} ({label}): {state} (wealth: {w.shown}; Fig. 7 at 90 deg: "
                       f"{f.shown})")
        details.extend(f"  {axis} {v:g}, {d}" for d in w.details + f.details)
    ran = [s for s in states if s[1] != NOT_RUN]
    if not ran:
        return Verdict(NOT_RUN, details=details)
    broke = [s for s in ran if s[1] == "breaks"]
    gaps = [f"{what} not run at {axis} {', '.join(f'{s[0]:g}' for s in states if s[i].answer == NOT_RUN)}"
            for what, i in (("wealth", 2), ("Fig. 7", 3)) if any(s[i].answer == NOT_RUN for s in states)]
    note = "; ".join(gaps)
    if broke:
        v, _, w, f = broke[0]
        why = w if w.answer == NO else f
        below = [s for s in states if s[0] < v and NOT_RUN in (s[2].answer, s[3].answer)]
        if below:  # the smallest breaking value may lie below, where a half of the rule was not run
            note = "; ".join(x for x in (note, f"breaks at or below {v:g}: a value below it is not fully run") if x)
        return Verdict(YES, n=why.n, effect=f"breaks at {axis} {v:g}: {why.effect}", details=details, note=note,
                       value=v)
    if all(s[1].startswith("holds") for s in ran):
        if any(s[2].answer == NOT_RUN for s in states):  # "no" needs the wealth rule at every value
            return Verdict(INCONCLUSIVE, effect=f"holds at every {axis} value run", details=details, note=note)
        return Verdict(NO, effect=f"holds at every {axis} value run", details=details, note=note)
    return Verdict(INCONCLUSIVE, details=details, note=note)


def partition_questions(runs: pd.DataFrame, chain: pd.DataFrame | None, decl: dict) -> tuple[Verdict, Verdict]:
    """partition_forks and partition_rich: "pending" until the store holds chain_partition's runs (and,
    for the forks, the per-run chain measures)."""
    part = runs[runs["experiment"] == PARTITION] if "experiment" in runs.columns else runs.iloc[0:0]
    if part.empty or "partition" not in part.columns:
        why = "the store holds no runs of chain_partition (infomarket sweep chain_partition)"
        return Verdict(PENDING, note=why), Verdict(PENDING, note=why)
    bases = sorted(part["base"].unique()) if "base" in part.columns else ["all"]

    def sel(df, b, p):
        return df[((df["base"] == b) if "base" in df.columns else True) & (df["partition"] == p)]

    m = _margin(decl, 5)
    rich_up, rich_down, tost_ok, det = [], [], [], []
    for b in bases:
        x, y = sel(part, b, "on")["byz_share"].to_numpy(float), sel(part, b, "none")["byz_share"].to_numpy(float)
        rich_up.append(st.compare(x, y, alternative="greater", shift=-m, label=f"{b}: partition > none + {m:g}"))
        rich_down.append(st.compare(x, y, alternative="less", shift=m, label=f"{b}: partition < none - {m:g}"))
        tost_ok.append(st.tost(x, y, m)[0] < decl["study"]["alpha"] / 2)
        det.append(rich_up[-1].describe(" pp"))
    adj = st.adjust(rich_up + rich_down)
    rich = Verdict(st.answer(any(c.significant for c in adj), all(tost_ok)), details=det)
    if chain is None or chain.empty or "reorganised_tx" not in chain.columns:
        return Verdict(PENDING, note="the store holds no per-run chain measures (reorganised_tx, forks)"), rich
    c = chain[chain["experiment"] == PARTITION]
    ups, nots, det = [], [], []
    for b in bases:
        x, y = sel(c, b, "on")["reorganised_tx"].to_numpy(float), sel(c, b, "none")["reorganised_tx"].to_numpy(float)
        r = max(1.0, 0.1 * float(np.median(y))) if len(y) else 1.0
        ups.append(st.compare(x, y, alternative="greater", label=f"{b}: reorganised tx, partition > none"))
        nots.append(st.compare(x, y, alternative="less", shift=-r, label=f"{b}: partition < none + {r:g}"))
        det.append(ups[-1].describe(" tx"))
    ups, nots = st.adjust(ups), st.adjust(nots)
    causes = any(u.significant and u.median_x > 0 for u in ups)
    forks = Verdict(st.answer(causes, all(n.significant for n in nots)), details=det)
    return forks, rich


@dataclass
class Answers:
    """The chain study's answers: the summary table, each question's verdict, the per-run table they rest on, and
    the declarations' status."""
    table: pd.DataFrame           # question, setting/axis, rule, n, effect, answer
    verdicts: dict[str, Verdict]
    runs: pd.DataFrame
    locks: str = ""


RULES = {
    "wealth": "holds per condition if chain < instant + k pp (MW, Holm over 6); breaks if chain > instant + k pp; "
              "yes = all 6 hold, no = any breaks",
    "fig7": "helps if staking > no staking (MW, Holm over 45/90 deg); no if gain < d shown (d = 10 % of instant "
            "no-staking median); yes = helps at both",
    "breaks": "at each value: wealth rule on Figs. 3C/4C (Holm over 2) and Fig. 7 rule at 90 deg; answer = "
              "smallest value where either says no",
    "partition_forks": "reorganised tx partition > none (MW, Holm over 2 bases) with median > 0; no = "
                       "partition < none + max(1, 10 %) at both",
    "partition_rich": "changes if |byz share shift| > 5 pp shown (Holm over 4); no = TOST within 5 pp at both bases",
}


def answer(runs: pd.DataFrame, chain: pd.DataFrame | None = None, decl: dict | None = None) -> Answers:
    """Every declared question answered from per-run values (``per_run`` of the stores' robots)."""
    decl = decl or declaration()
    q = decl["questions"]
    v: dict[str, Verdict] = {}
    v["wealth_toychain"] = wealth_question(runs, decl, "toychain")
    v["wealth_geth_argos"] = wealth_question(runs, decl, "geth_argos")
    v["fig7_toychain"] = fig7_question(runs, decl, "toychain", q["fig7_toychain"]["angles"])
    v["fig7_geth_argos"] = fig7_question(runs, decl, "geth_argos", q["fig7_geth_argos"]["angles"])
    for axis in ("period", "loss", "gas"):
        v[f"breaks_{axis}"] = breaks_question(runs, decl, axis)
    v["partition_forks"], v["partition_rich"] = partition_questions(runs, chain, decl)
    rows = []
    for qid, verdict in v.items():
        rule = RULES["wealth" if qid.startswith("wealth") else "fig7" if qid.startswith("fig7") else
                     "breaks" if qid.startswith("breaks") else qid]
        shown = verdict.shown
        if qid.startswith("breaks") and verdict.answer == YES:
            shown = f"yes, at {qid.split('_')[1]} {verdict.value:g}" + (f" ({verdict.note})" if verdict.note else "")
        rows.append({"question": qid, "text": q[qid]["question"], "rule": rule, "n": verdict.n,
                     "effect (95 % interval)": verdict.effect, "answer": shown})
    return Answers(pd.DataFrame(rows), v, runs)


def markdown(a: Answers, wall: str = "") -> str:
    """The answers as ``chain-study.md``: the table, each verdict's details, then the declaration's amendments and
    deviations."""
    lines = ["# Chain study: answers", "",
             "Questions and rules: `src/infomarket/analysis/chain_questions.toml` (declared before the runs; "
             "its amendments and deviations are listed at the end).", ""]
    if a.locks:
        lines += [a.locks, ""]
    if wall:
        lines += [wall, ""]
    lines += ["| question | rule | n (runs per group) | effect (95 % interval) | answer |", "|---|---|---|---|---|"]
    for qid, text, rule, n, effect, shown in a.table.itertuples(index=False, name=None):
        lines.append(f"| {qid}: {text} | {rule} | {n} | {effect} | **{shown}** |")
    lines += [""]
    for qid, verdict in a.verdicts.items():
        lines += [f"## {qid}: {verdict.shown}", ""]
        lines += [f"- {d}" for d in verdict.details] + [""]
    lines += DECLARATION.record_markdown()
    return "\n".join(lines)


