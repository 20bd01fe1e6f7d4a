"""The paper's open questions: the ``future`` sweep's figures and its declared questions.

The sweep (``infomarket sweep future``) runs three attacks (``future_liar``, ``future_farmer``,
``future_surfer``) against four defences, plus every defence without Byzantines (``future_honest``).
The sample is the run: its swarm items (every robot's items after the transitory period, as in Fig. 7).
The questions, their decision rules and parameters are declared in ``tolerances.toml`` ([statistics],
[questions.*]); each answer here is computed from those parameters with ``analysis.stats`` (run-level
effects with bootstrap intervals, one-sided Mann-Whitney, Holm over the question's family, simulated
power, non-inferiority tests for "no cost" and "kept"): yes, no or inconclusive, whatever it is.
"""
from __future__ import annotations

import html
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from scipy import stats as sps

from . import stats as st
from .boxplots import draw_boxes, legend_handles
from .declared import size_note, status_of
from .figures import _runs_text, figure_parts
from .frames import Frames, MissingDataError
from .headline import DECLARATION
from .study import NO_DATA, Declaration, Verdict, html_table, md_table
from ..errors import ConfigError

TOLERANCES = DECLARATION.path
ATTACKS = {"future_liar": "constant liar (scaboteur)", "future_farmer": "reputation farmer",
           "future_surfer": "Theta-surfer"}
HONEST = "future_honest"
DEFENCES = ("paper", "reputation_sceptic", "adaptive_theta", "both")
NEW = DEFENCES[1:]
COLOURS = {"paper": "#7f7f7f", "reputation_sceptic": "#1f77b4", "adaptive_theta": "#2ca02c", "both": "#9467bd"}
LABELS = {"paper": "paper (sceptical + outlier, staking)", "reputation_sceptic": "reputation-aware sceptic",
          "adaptive_theta": "adaptive Theta", "both": "both"}
#: each defence's reference line (its median without Byzantines): a style of its own, not colour alone
STYLES = {"paper": (0, (6, 2)), "reputation_sceptic": (0, (2, 1.5)), "adaptive_theta": (0, (6, 2, 1.5, 2)),
          "both": (0, (1, 1))}
BELOW = (5.0, 10.0, 20.0, 25.0)
ABOVE = (40.0, 90.0)
YES, NO, INCONCLUSIVE = st.YES, st.NO, st.INCONCLUSIVE


def swarm_items(robots: pd.DataFrame) -> pd.DataFrame:
    """One row per run of the future experiments: experiment, defence, byzantines, rotation_angle
    (NaN without Byzantines) and ``items``, the swarm's items after the transitory period."""
    if robots.empty or "experiment" not in robots.columns:
        raise MissingDataError("no future-sweep runs in the store")
    rows = robots[robots["experiment"].isin([*ATTACKS, HONEST])]
    if rows.empty or "defence" not in rows.columns:
        raise MissingDataError("no future-sweep runs in the store")
    rows = rows.assign(rotation_angle=rows["rotation_angle"] if "rotation_angle" in rows.columns else math.nan)
    keys = ["experiment", "defence", "byzantines", "rotation_angle", "condition", "run"]
    out = rows.groupby(keys, observed=True, dropna=False)["items_collected"].sum().rename("items").reset_index()
    return out.astype({"byzantines": int})


def values(runs: pd.DataFrame, experiment: str, defence: str, byzantines: int,
           angle: float | None = None) -> np.ndarray:
    """Per-run swarm items of one condition (empty when the store lacks it)."""
    sel = runs[(runs["experiment"] == experiment) & (runs["defence"] == defence)
               & (runs["byzantines"] == byzantines)]
    if angle is not None:
        sel = sel[np.isclose(sel["rotation_angle"], angle)]
    return sel["items"].to_numpy(float)


def _need(x: np.ndarray, what: str) -> np.ndarray:
    if len(x) < 2:
        raise MissingDataError(f"fewer than 2 runs of {what}")
    return x


def greater(a: np.ndarray, b: np.ndarray) -> float:
    """One-sided Mann-Whitney U p-value that runs ``a`` tend to collect more than runs ``b``."""
    return float(sps.mannwhitneyu(a, b, alternative="greater").pvalue)


# ----------------------------------------------------------------------------------------- questions
@dataclass(frozen=True)
class Question:
    """One declared open question: its id, its text, the rule that answers it and the rule's parameters."""
    id: str
    question: str
    rule: str
    params: dict


STATISTICS = {"alpha": st.ALPHA, "power": st.POWER, "margin_fraction": 0.10, "confidence": st.CONFIDENCE,
              "runs": None}


def _declaration(path: str | Path) -> Declaration:
    return DECLARATION if Path(path) == TOLERANCES else Declaration.read(path)


def load_statistics(path: str | Path = TOLERANCES) -> dict:
    """The shared statistical declarations ([statistics]) of the questions, with defaults."""
    return {**STATISTICS, **_declaration(path).data.get("statistics", {})}


def load_questions(path: str | Path = TOLERANCES) -> dict[str, Question]:
    """The declared questions; each one's params include the shared [statistics] (its own win)."""
    shared = load_statistics(path)
    data = _declaration(path).questions
    out = {}
    for qid, spec in data.items():
        params = {**shared, **{k: v for k, v in spec.items() if k not in ("question", "rule")}}
        out[qid] = Question(qid, spec["question"], spec["rule"], params)
    return out


ANSWERS: dict[str, Callable[[pd.DataFrame, dict], Verdict]] = {}


def answers(qid: str):
    """Decorator: register the function as the answer to the question ``qid`` (in ``ANSWERS``)."""
    def register(fn):
        ANSWERS[qid] = fn
        return fn
    return register


def _med(x: np.ndarray) -> float:
    return float(np.median(x))


def _reference(runs: pd.DataFrame, p: dict) -> tuple[np.ndarray, float]:
    """The paper defence's swarm without Byzantines, and the margin (a fraction of its median)."""
    ref = _need(values(runs, HONEST, "paper", 0), "future_honest, paper defence")
    return ref, p.get("fraction", p["margin_fraction"]) * _med(ref)


def _cmp(x, y, label, p, *, alternative="greater", shift=0.0, declared=None, family=1) -> st.Comparison:
    return st.compare(x, y, alternative=alternative, shift=shift, declared=declared, alpha=p["alpha"],
                      family=family, label=label)


def _lines(comps: list[st.Comparison]) -> str:
    return "; ".join(c.describe(" items") for c in comps)


def _size(p: dict, comps: list[st.Comparison]) -> str:
    note = size_note(p.get("runs"), [n for c in comps for n in (c.n_x, c.n_y)])
    return f"NOTE: {note}. " if note else ""


def _power_line(comps: list[st.Comparison], p: dict) -> str:
    low = [c.label for c in comps if not c.power >= p["power"]]
    return (f"power >= {p['power']:g} at {len(comps) - len(low)} of {len(comps)} comparisons"
            + (f" (below at {', '.join(low)})" if low else ""))


@answers("liar_recovered")
def _liar_recovered(runs: pd.DataFrame, p: dict) -> Verdict:
    ref, m = _reference(runs, p)
    keys = [(d, a) for d in NEW for a in BELOW]
    xs = {k: _need(values(runs, "future_liar", k[0], 3, k[1]), f"future_liar {k[0]} at {k[1]:g} deg") for k in keys}
    ni = st.adjust([_cmp(xs[k], ref, f"{k[0]} {k[1]:g} deg within", p, shift=m, declared=0.0, family=len(keys))
                    for k in keys])
    below = st.adjust([_cmp(xs[k], ref, f"{k[0]} {k[1]:g} deg below", p, alternative="less", shift=m)
                       for k in keys])
    yes = [d for d in NEW if all(c.significant for c, k in zip(ni, keys) if k[0] == d)]
    no = all(any(c.significant for c, k in zip(below, keys) if k[0] == d) for d in NEW)
    shown_below = [d for d in NEW if any(c.significant for c, k in zip(below, keys) if k[0] == d)]
    return Verdict(st.answer(bool(yes), no),
                  f"{_size(p, ni)}reference (paper, 0 Byzantines) median {_med(ref):g} items, n = {len(ref)}; "
                  f"margin {m:.3g} items; shown within the margin at every angle: {', '.join(yes) or 'no defence'}; "
                  f"shown below at some angle: {', '.join(shown_below) or 'no defence'}; "
                  f"{_power_line(ni, p)}. Non-inferiority (Holm over {len(keys)}): {_lines(ni)}", tuple(ni + below))


def _improves(defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Verdict:
        _, m = _reference(runs, p)
        comps = []
        for a in BELOW:
            x = _need(values(runs, "future_liar", defence, 3, a), f"future_liar {defence} at {a:g} deg")
            y = _need(values(runs, "future_liar", "paper", 3, a), f"future_liar paper at {a:g} deg")
            comps.append(_cmp(x, y, f"{a:g} deg", p, declared=m, family=len(BELOW)))
        comps = st.adjust(comps)
        hits = sum(c.significant for c in comps)
        return Verdict(st.answer_superiority(comps, p["min_angles"], p["power"]),
                      f"{_size(p, comps)}{hits} of {len(BELOW)} angles with Holm-adjusted p < {p['alpha']:g} "
                      f"(needed {p['min_angles']}); {_power_line(comps, p)} for a gain of the margin "
                      f"({m:.3g} items). {defence} vs paper: {_lines(comps)}", tuple(comps))
    return measure


for _d in NEW:
    answers(f"liar_improved_{_d}")(_improves(_d))


def _beats(experiment: str, defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Verdict:
        own = _need(values(runs, HONEST, defence, 0), f"future_honest, {defence}")
        m = p.get("fraction", p["margin_fraction"]) * _med(own)
        angles = (*BELOW, *ABOVE)
        x = {a: _need(values(runs, experiment, defence, 3, a), f"{experiment} {defence} at {a:g} deg") for a in angles}
        y = {a: _need(values(runs, experiment, "paper", 3, a), f"{experiment} paper at {a:g} deg") for a in angles}
        dropped = st.adjust([_cmp(x[a], own, f"{a:g} deg", p, alternative="less", shift=m) for a in angles])
        kept = st.adjust([_cmp(x[a], own, f"{a:g} deg", p, shift=m) for a in angles])
        not_better = st.adjust([_cmp(x[a], y[a], f"{a:g} deg", p, alternative="less", shift=-m) for a in angles])
        helped = st.adjust([_cmp(x[a], y[a], f"{a:g} deg", p, declared=m, family=len(angles)) for a in angles])

        def at(comps):
            hit = [c.label for c in comps if c.significant]
            return ", ".join(hit) if hit else "no angle"

        yes = any(c.significant for c in dropped) and all(c.significant for c in not_better)
        no = any(c.significant for c in helped) or all(c.significant for c in kept)
        return Verdict(st.answer(yes, no),
                      f"{_size(p, helped)}{defence} without Byzantines: median {_med(own):g}, margin {m:.3g}; "
                      f"shown below {_med(own):g} - margin at {at(dropped)}; shown above it at {at(kept)}; "
                      f"shown no better than the paper + margin at {at(not_better)}; significantly better than "
                      f"the paper at {at(helped)} (each set Holm over {len(angles)} angles). {defence} vs paper: "
                      f"{_lines(helped)}", tuple(dropped + kept + not_better + helped))
    return measure


answers("farmer_beats_reputation_sceptic")(_beats("future_farmer", "reputation_sceptic"))
answers("surfer_beats_adaptive_theta")(_beats("future_surfer", "adaptive_theta"))


def _honest_cost(defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Verdict:
        x, m = _reference(runs, p)
        y = _need(values(runs, HONEST, defence, 0), f"future_honest, {defence}")
        cost = _cmp(y, x, f"{defence} below paper", p, alternative="less", declared=-m)
        ni = _cmp(y, x, f"{defence} within the margin of paper", p, shift=m, declared=0.0)
        rel = 100.0 * (_med(y) - _med(x)) / _med(x) if _med(x) else math.nan
        return Verdict(st.answer(cost.significant, ni.significant),
                      f"{_size(p, [cost])}medians {_med(y):g} ({defence}) vs {_med(x):g} (paper), {rel:+.1f} %; "
                      f"margin {m:.3g} items. {cost.describe(' items')}; {ni.describe(' items')}", (cost, ni))
    return measure


for _d in NEW:
    answers(f"honest_cost_{_d}")(_honest_cost(_d))


@answers("above_theta_kept")
def _above_kept(runs: pd.DataFrame, p: dict) -> Verdict:
    _, m = _reference(runs, p)
    keys = [(d, a) for d in NEW for a in ABOVE]
    x = {k: _need(values(runs, "future_liar", k[0], 3, k[1]), f"future_liar {k[0]} at {k[1]:g} deg") for k in keys}
    y = {a: _need(values(runs, "future_liar", "paper", 3, a), f"future_liar paper at {a:g} deg") for a in ABOVE}
    ni = st.adjust([_cmp(x[k], y[k[1]], f"{k[0]} {k[1]:g} deg", p, shift=m, declared=0.0, family=len(keys))
                    for k in keys])
    worse = st.adjust([_cmp(x[k], y[k[1]], f"{k[0]} {k[1]:g} deg", p, alternative="less") for k in keys])
    shown = [c.label for c in worse if c.significant]
    return Verdict(st.answer(all(c.significant for c in ni), bool(shown)),
                  f"{_size(p, ni)}margin {m:.3g} items; significantly worse than the paper: "
                  f"{', '.join(shown) or 'none'}; non-inferiority shown at {sum(c.significant for c in ni)} of "
                  f"{len(ni)}; {_power_line(ni, p)}. Non-inferiority (Holm over {len(keys)}): {_lines(ni)}",
                  tuple(ni + worse))


def question_table(source, questions: dict[str, Question] | None = None) -> pd.DataFrame:
    """One row per declared question: the question, its rule, the answer (yes / no / inconclusive, or
    ``no data`` when the store lacks a condition it needs), its statistics, and whether its declaration
    predates the store's first run (``declared``: see ``analysis.declared``)."""
    frames = Frames.of(source)
    questions = load_questions() if questions is None else questions
    locks = DECLARATION.locks(frames.meta.get("declarations") if frames.meta else None)
    try:
        runs = swarm_items(frames.robots)
    except MissingDataError as exc:
        runs, missing = None, str(exc)
    rows = []
    for qid, q in questions.items():
        if qid not in ANSWERS:
            raise ConfigError(f"tolerances questions.{qid} has no answer function in future.py")
        if runs is None:
            a = Verdict(NO_DATA, missing)
        else:
            try:
                a = ANSWERS[qid](runs, q.params)
            except MissingDataError as exc:
                a = Verdict(NO_DATA, str(exc))
        note = st.N_TOO_SMALL if a.answer == INCONCLUSIVE and st.too_few_runs(a.comparisons) else ""
        rows.append([qid, q.question, q.rule, a.answer, a.statistics,
                     status_of(locks, "tolerances.toml", f"questions.{qid}"), note])
    return pd.DataFrame(rows, columns=["id", "question", "rule", "answer", "statistics", "declared", "note"])


def _shown(table: pd.DataFrame) -> pd.DataFrame:
    """The table as printed: each answer with its note (``inconclusive (n too small)``)."""
    out = table.copy()
    out["answer"] = [st.shown(a, n) for a, n in zip(table["answer"], table["note"])]
    return out


# ------------------------------------------------------------------------------------------- figures
def attack_figure(robots: pd.DataFrame, experiment: str) -> Figure:
    """Fig. 7-like: swarm items after the transitory period against rotation angle, one box per defence,
    (A) one and (B) three Byzantines; dashed lines: each defence's median without Byzantines."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    runs = swarm_items(robots)
    att = runs[runs["experiment"] == experiment]
    if att.empty:
        raise MissingDataError(f"no {experiment} runs in the store")
    honest = runs[runs["experiment"] == HONEST]
    fig = Figure(figsize=(12.0, 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2, sharey=True)
    angles = np.sort(att["rotation_angle"].dropna().unique())
    pos = np.arange(len(angles), dtype=float)
    width = 0.8 / len(DEFENCES)
    for ax, (letter, byz) in zip(axes, [("A", 1), ("B", 3)]):
        panel = att[att["byzantines"] == byz]
        counts = []
        for k, d in enumerate(DEFENCES):
            sel = panel[panel["defence"] == d]
            data = [sel.loc[np.isclose(sel["rotation_angle"], a), "items"].to_numpy() for a in angles]
            counts += [len(x) for x in data]
            draw_boxes(ax, data, pos + (k - 1.5) * width, COLOURS[d], width=width * 0.9)
        ax.set_title(f"({letter}) {byz} Byzantine{'s' if byz > 1 else ''}, {_runs_text(counts)} per box",
                     loc="left", fontsize=10)
        for d in DEFENCES:
            base = honest.loc[honest["defence"] == d, "items"]
            if len(base):
                ax.axhline(float(base.median()), color=COLOURS[d], linestyle=STYLES[d], linewidth=1.2, zorder=0)
        below = [i for i, a in enumerate(angles) if a < 30.0]
        if below and len(below) < len(angles):
            ax.axvline(below[-1] + 0.5, color="grey", linestyle=":", linewidth=1)
        ax.set_xticks(pos, [f"{a:g}" for a in angles])
        ax.set_xlabel("rotation angle of the Byzantine robots (deg)")
    axes[0].set_ylabel("items collected by the swarm\n(last 10 000 of 30 000 steps)")
    handles = legend_handles({COLOURS[d]: LABELS[d] for d in DEFENCES})
    handles += [Line2D([], [], color=COLOURS[d], linestyle=STYLES[d], linewidth=1.2,
                       label=f"{LABELS[d]}: median without Byzantines") for d in DEFENCES]
    handles += [Line2D([], [], color="grey", linestyle=":", label="Theta = 30 deg")]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, frameon=False, fontsize=8)
    fig.suptitle(f"The paper's open questions: {ATTACKS[experiment]} against four defences", fontsize=11)
    return fig


def figure_specs():
    """(name, caption, draw) of each attack's figure, for the report."""
    return [(f"{name}", f"Swarm items after the transitory period vs rotation angle, attack: {label}; "
             "boxes per defence; lines (one style per defence): each defence's median without Byzantines; "
             "32 runs per box at full scale.", (lambda f, n=name: attack_figure(f.robots, n)))
            for name, label in ATTACKS.items()]


def has_data(frames: Frames) -> bool:
    """Whether the tables hold runs of the open-questions sweep (the attacks or the honest swarm), so the report
    adds its section."""
    r = frames.robots
    return not r.empty and "experiment" in r.columns and r["experiment"].isin([*ATTACKS, HONEST]).any()


# -------------------------------------------------------------------------------------------- report
@dataclass
class Section:
    """The report's section on the open questions: figures written and the answered questions."""

    figures: list[tuple[str, str, list[Path], str]]  # name, caption, files (empty if skipped), note
    table: pd.DataFrame
    lock: str = ""  # whether the questions were declared before the store's first run


def section(frames: Frames, parts: list, vector: str, echo: Callable[[str], None]) -> Section | None:
    """Draw each attack's figure (its files added to ``parts``, a study ``Report``'s) and answer the declared
    questions; None when the store has no future-sweep runs (a paper-only store's report is unchanged)."""
    if not has_data(frames):
        return None
    figs = []
    for name, caption, draw in figure_specs():
        try:
            drawn = figure_parts(draw(frames), name, vector)
            parts += drawn
            files = [Path(file) for file, _ in drawn]
            figs.append((name, caption, files, ""))
            echo(f"{name}: wrote {', '.join(p.name for p in files)}")
        except MissingDataError as exc:
            figs.append((name, caption, [], str(exc)))
            echo(f"{name}: skipped ({exc})")
    table = question_table(frames)
    counts = table["answer"].value_counts()
    small = int((table["note"] == st.N_TOO_SMALL).sum())
    echo(f"open questions: {counts.get(YES, 0)} yes, {counts.get(NO, 0)} no, {counts.get(INCONCLUSIVE, 0)} "
         f"inconclusive{f' ({small} with n too small to reach alpha)' if small else ''}, "
         f"{counts.get(NO_DATA, 0)} no data")
    lock = DECLARATION.lock_summary(frames.meta.get("declarations") if frames.meta else None, "questions.")
    return Section(figs, table, lock)


INTRO = ("The paper's future work, run: reputation-aware scepticism and adaptive Theta against attacks aimed at "
         "them (docs/research.md). Questions and decision rules: `src/infomarket/analysis/tolerances.toml` "
         "([statistics], [questions]); the rules were revised after the first full sweep (the amendments are "
         "listed at the end of this report). "
         "The sample is the run (swarm items in the last 10 000 steps). Each comparison gives the Hodges-Lehmann "
         "shift and Cliff's delta with 95 % bootstrap intervals, a one-sided Mann-Whitney U test (Holm-adjusted "
         "over the angles or defences the question spans), and its simulated power for the declared margin; "
         "an answer the runs cannot support either way is \"inconclusive\", never \"no\".")
COLUMNS = ["question", "answer", "declared", "statistics", "rule"]


def to_markdown(s: Section) -> list[str]:
    """The open-questions section as Markdown lines: each figure (or why it was skipped), then the answers table."""
    md = ["## The paper's open questions: reputation-aware defences", "", INTRO, ""]
    for name, caption, files, note in s.figures:
        md += [f"### {name}", "", caption, ""]
        md += [f"![{name}]({files[0].name})", "", f"Vector: [{files[1].name}]({files[1].name})"] if files \
            else [f"*Skipped: {note}.*"]
        md.append("")
    md += ["### Answers", "", f"Declarations: {s.lock}.", "", md_table(_shown(s.table)[COLUMNS]), ""]
    return md


def to_html(s: Section) -> list[str]:
    """The open-questions section as HTML fragments, the same content as ``to_markdown``."""
    e = html.escape
    parts = ["<h2>The paper's open questions: reputation-aware defences</h2>", f"<p>{e(INTRO)}</p>"]
    for name, caption, files, note in s.figures:
        parts.append(f"<h3>{e(name)}</h3><p>{e(caption)}</p>")
        if files:
            parts.append(f"<p><a href='{e(files[1].name)}'><img src='{e(files[0].name)}' alt='{e(name)}'></a></p>")
        else:
            parts.append(f"<p class='note'>Skipped: {e(note)}.</p>")
    parts += ["<h3>Answers</h3>", f"<p>Declarations: {e(s.lock)}.</p>", html_table(_shown(s.table)[COLUMNS])]
    return parts
