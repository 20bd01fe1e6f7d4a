"""The paper's open questions (issue 10): the ``future`` sweep's figures and its declared questions.

The sweep (``infomarket sweep future``) runs three attacks (``future_liar``, ``future_farmer``,
``future_surfer``) against four defences, plus every defence without Byzantines (``future_honest``).
The sample is the run: its swarm items (every robot's items after the transitory period, as in Fig. 7).
The questions, their decision rules and parameters are declared in ``tolerances.toml`` ([questions.*])
before the full sweep ran; each answer here is computed from those parameters, yes or no, with the
Mann-Whitney p-values and medians it used, whatever it is.
"""
from __future__ import annotations

import math
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from scipy import stats as sps

from .boxplots import draw_boxes, legend_handles
from .frames import Frames, MissingDataError

TOLERANCES = Path(__file__).with_name("tolerances.toml")
ATTACKS = {"future_liar": "constant liar (scaboteur)", "future_farmer": "reputation farmer",
           "future_surfer": "Theta-surfer"}
HONEST = "future_honest"
DEFENCES = ("paper", "reputation_sceptic", "adaptive_theta", "both")
NEW = DEFENCES[1:]
COLOURS = {"paper": "#7f7f7f", "reputation_sceptic": "#1f77b4", "adaptive_theta": "#2ca02c", "both": "#9467bd"}
LABELS = {"paper": "paper (sceptical + outlier, staking)", "reputation_sceptic": "reputation-aware sceptic",
          "adaptive_theta": "adaptive Theta", "both": "both"}
BELOW = (5.0, 10.0, 20.0, 25.0)
ABOVE = (40.0, 90.0)
YES, NO, NO_DATA = "yes", "no", "no data"


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
    id: str
    question: str
    rule: str
    params: dict


@dataclass(frozen=True)
class Answer:
    answer: str      # yes / no / no data
    statistics: str  # the numbers the answer rests on


def load_questions(path: str | Path = TOLERANCES) -> dict[str, Question]:
    data = tomllib.loads(Path(path).read_text()).get("questions", {})
    out = {}
    for qid, spec in data.items():
        params = {k: v for k, v in spec.items() if k not in ("question", "rule")}
        out[qid] = Question(qid, spec["question"], spec["rule"], params)
    return out


ANSWERS: dict[str, Callable[[pd.DataFrame, dict], Answer]] = {}


def answers(qid: str):
    def register(fn):
        ANSWERS[qid] = fn
        return fn
    return register


def _med(x: np.ndarray) -> float:
    return float(np.median(x))


@answers("liar_recovered")
def _liar_recovered(runs: pd.DataFrame, p: dict) -> Answer:
    ref = _need(values(runs, HONEST, "paper", 0), "future_honest, paper defence")
    target = (1.0 - p["fraction"]) * _med(ref)
    parts, any_yes = [], False
    for d in NEW:
        ratios = []
        for a in BELOW:
            x = _need(values(runs, "future_liar", d, 3, a), f"future_liar {d} at {a:g} deg")
            ratios.append((_med(x) / _med(ref), a, greater(x, values(runs, "future_liar", "paper", 3, a))))
        worst = min(ratios)
        ok = all(r * _med(ref) >= target for r, _, _ in ratios)
        any_yes |= ok
        parts.append(f"{d}: worst median ratio {worst[0]:.2f} at {worst[1]:g} deg "
                     f"(p vs paper, one-sided: {', '.join(f'{a:g}: {q:.2g}' for _, a, q in ratios)})")
    return Answer(YES if any_yes else NO, f"reference median {_med(ref):g} items (paper, 0 Byzantines, "
                  f"n = {len(ref)}), target >= {target:g}; " + "; ".join(parts))


def _improves(defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Answer:
        hits, parts = 0, []
        for a in BELOW:
            x = _need(values(runs, "future_liar", defence, 3, a), f"future_liar {defence} at {a:g} deg")
            y = _need(values(runs, "future_liar", "paper", 3, a), f"future_liar paper at {a:g} deg")
            q = greater(x, y)
            hits += q < p["alpha"]
            parts.append(f"{a:g} deg: {_med(x):g} vs {_med(y):g}, p = {q:.2g}")
        return Answer(YES if hits >= p["min_angles"] else NO,
                      f"{hits} of {len(BELOW)} angles with p < {p['alpha']:g} (medians {defence} vs paper, "
                      f"n = {len(x)} runs each): " + "; ".join(parts))
    return measure


for _d in NEW:
    answers(f"liar_improved_{_d}")(_improves(_d))


def _beats(experiment: str, defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Answer:
        own = _need(values(runs, HONEST, defence, 0), f"future_honest, {defence}")
        floor = (1.0 - p["fraction"]) * _med(own)
        dropped, helped, parts = [], [], []
        for a in (*BELOW, *ABOVE):
            x = _need(values(runs, experiment, defence, 3, a), f"{experiment} {defence} at {a:g} deg")
            y = _need(values(runs, experiment, "paper", 3, a), f"{experiment} paper at {a:g} deg")
            q = greater(x, y)
            if _med(x) < floor:
                dropped.append(a)
            if q < p["alpha"]:
                helped.append(a)
            parts.append(f"{a:g} deg: {_med(x):g} (paper {_med(y):g}, p = {q:.2g})")
        yes = bool(dropped) and not helped
        def at(angles):
            return f"{', '.join(f'{a:g}' for a in angles)} deg" if angles else "no angle"

        return Answer(YES if yes else NO,
                      f"{defence} without Byzantines: median {_med(own):g}, floor {floor:g}; below the floor at "
                      f"{at(dropped)}; significantly better than the paper at {at(helped)}; " + "; ".join(parts))
    return measure


answers("farmer_beats_reputation_sceptic")(_beats("future_farmer", "reputation_sceptic"))
answers("surfer_beats_adaptive_theta")(_beats("future_surfer", "adaptive_theta"))


def _honest_cost(defence: str):
    def measure(runs: pd.DataFrame, p: dict) -> Answer:
        x = _need(values(runs, HONEST, "paper", 0), "future_honest, paper")
        y = _need(values(runs, HONEST, defence, 0), f"future_honest, {defence}")
        q = greater(x, y)
        rel = 100.0 * (_med(y) - _med(x)) / _med(x) if _med(x) else math.nan
        return Answer(YES if q < p["alpha"] else NO,
                      f"medians {_med(y):g} ({defence}) vs {_med(x):g} (paper), {rel:+.1f} %; Mann-Whitney "
                      f"paper > {defence}: p = {q:.2g} (n = {len(x)}, {len(y)})")
    return measure


for _d in NEW:
    answers(f"honest_cost_{_d}")(_honest_cost(_d))


@answers("above_theta_kept")
def _above_kept(runs: pd.DataFrame, p: dict) -> Answer:
    worse, parts = [], []
    for d in NEW:
        for a in ABOVE:
            x = _need(values(runs, "future_liar", "paper", 3, a), f"future_liar paper at {a:g} deg")
            y = _need(values(runs, "future_liar", d, 3, a), f"future_liar {d} at {a:g} deg")
            q = greater(x, y)
            if q < p["alpha"]:
                worse.append(f"{d} at {a:g} deg")
            parts.append(f"{d} {a:g} deg: {_med(y):g} vs {_med(x):g}, p = {q:.2g}")
    return Answer(NO if worse else YES, f"significantly worse than the paper: {', '.join(worse) or 'none'}; "
                  + "; ".join(parts))


def question_table(source, questions: dict[str, Question] | None = None) -> pd.DataFrame:
    """One row per declared question: the question, its rule, the answer and its statistics
    (``no data`` when the store lacks a condition it needs)."""
    frames = Frames.of(source)
    questions = load_questions() if questions is None else questions
    try:
        runs = swarm_items(frames.robots)
    except MissingDataError as exc:
        runs, missing = None, str(exc)
    rows = []
    for qid, q in questions.items():
        if qid not in ANSWERS:
            raise KeyError(f"tolerances questions.{qid} has no answer function in future.py")
        if runs is None:
            a = Answer(NO_DATA, missing)
        else:
            try:
                a = ANSWERS[qid](runs, q.params)
            except MissingDataError as exc:
                a = Answer(NO_DATA, str(exc))
        rows.append([qid, q.question, q.rule, a.answer, a.statistics])
    return pd.DataFrame(rows, columns=["id", "question", "rule", "answer", "statistics"])


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
        ax.set_title(f"({letter}) {byz} Byzantine{'s' if byz > 1 else ''}", loc="left", fontsize=10)
        for k, d in enumerate(DEFENCES):
            sel = panel[panel["defence"] == d]
            data = [sel.loc[np.isclose(sel["rotation_angle"], a), "items"].to_numpy() for a in angles]
            draw_boxes(ax, data, pos + (k - 1.5) * width, COLOURS[d], width=width * 0.9)
            base = honest.loc[honest["defence"] == d, "items"]
            if len(base):
                ax.axhline(float(base.median()), color=COLOURS[d], linestyle="--", linewidth=1, zorder=0)
        below = [i for i, a in enumerate(angles) if a < 30.0]
        if below and len(below) < len(angles):
            ax.axvline(below[-1] + 0.5, color="grey", linestyle=":", linewidth=1)
        ax.set_xticks(pos, [f"{a:g}" for a in angles])
        ax.set_xlabel("rotation angle of the Byzantine robots (deg)")
    axes[0].set_ylabel("items collected by the swarm\n(last 10 000 of 30 000 steps)")
    handles = legend_handles({COLOURS[d]: LABELS[d] for d in DEFENCES})
    handles += [Line2D([], [], color="black", linestyle="--", label="median without Byzantines (same colour)"),
                Line2D([], [], color="grey", linestyle=":", label="Theta = 30 deg")]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, frameon=False, fontsize=8)
    fig.suptitle(f"The paper's open questions: {ATTACKS[experiment]} against four defences", fontsize=11)
    return fig


def figure_specs():
    """(name, caption, draw) of each attack's figure, for the report."""
    return [(f"{name}", f"Swarm items after the transitory period vs rotation angle, attack: {label}; "
             "boxes per defence, dashed lines: each defence's median without Byzantines, 32 runs per box "
             "at full scale.", (lambda f, n=name: attack_figure(f.robots, n)))
            for name, label in ATTACKS.items()]


def has_data(frames: Frames) -> bool:
    r = frames.robots
    return not r.empty and "experiment" in r.columns and r["experiment"].isin([*ATTACKS, HONEST]).any()


# -------------------------------------------------------------------------------------------- report
@dataclass
class Section:
    """The report's section on the open questions: figures written and the answered questions."""

    figures: list[tuple[str, str, list[Path], str]]  # name, caption, files (empty if skipped), note
    table: pd.DataFrame


def section(frames: Frames, out: Path, vector: str, echo: Callable[[str], None]) -> Section | None:
    """Draw each attack's figure and answer the declared questions; None when the store has no
    future-sweep runs (a paper-only store's report is unchanged)."""
    from .figures import save

    if not has_data(frames):
        return None
    figs = []
    for name, caption, draw in figure_specs():
        try:
            files = save(draw(frames), out, name, vector)
            figs.append((name, caption, files, ""))
            echo(f"{name}: wrote {', '.join(p.name for p in files)}")
        except MissingDataError as exc:
            figs.append((name, caption, [], str(exc)))
            echo(f"{name}: skipped ({exc})")
    table = question_table(frames)
    counts = table["answer"].value_counts()
    echo(f"open questions: {counts.get(YES, 0)} yes, {counts.get(NO, 0)} no, {counts.get(NO_DATA, 0)} no data")
    return Section(figs, table)


INTRO = ("The paper's future work, run: reputation-aware scepticism and adaptive Theta against attacks aimed at "
         "them (docs/research.md). Questions and decision rules were declared in "
         "`src/infomarket/analysis/tolerances.toml` ([questions]) before the full sweep was run; the sample is "
         "the run (swarm items in the last 10 000 steps), tests are one-sided Mann-Whitney U on per-run values.")


def to_markdown(s: Section, md_table: Callable[[pd.DataFrame], str]) -> list[str]:
    md = ["## The paper's open questions: reputation-aware defences", "", INTRO, ""]
    for name, caption, files, note in s.figures:
        md += [f"### {name}", "", caption, ""]
        md += [f"![{name}]({files[0].name})", "", f"Vector: [{files[1].name}]({files[1].name})"] if files \
            else [f"*Skipped: {note}.*"]
        md.append("")
    md += ["### Answers", "", md_table(s.table[["question", "answer", "statistics", "rule"]]), ""]
    return md


def to_html(s: Section, html_table: Callable[[pd.DataFrame], str]) -> list[str]:
    import html

    e = html.escape
    parts = ["<h2>The paper's open questions: reputation-aware defences</h2>", f"<p>{e(INTRO)}</p>"]
    for name, caption, files, note in s.figures:
        parts.append(f"<h3>{e(name)}</h3><p>{e(caption)}</p>")
        if files:
            parts.append(f"<p><a href='{e(files[1].name)}'><img src='{e(files[0].name)}' alt='{e(name)}'></a></p>")
        else:
            parts.append(f"<p class='note'>Skipped: {e(note)}.</p>")
    parts += ["<h3>Answers</h3>", html_table(s.table[["question", "answer", "statistics", "rule"]])]
    return parts
