"""The paper's Figs. 2-7, each a function from DataFrames to a matplotlib ``Figure``.

Figures are built with ``matplotlib.figure.Figure`` rather than pyplot, so nothing here changes the
global backend: a notebook shows the returned figure inline, and ``save`` renders with Agg.  A panel
without data shows "no data in the store"; a figure without any data raises ``MissingDataError``.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..store.files import write_atomic
from . import metrics, stats
from .headline import load_rules
from .metrics import THETA_DEG
from .boxplots import BYZANTINE, HONEST, draw_boxes, honest_vs_byzantine, legend_handles
from .frames import Frames, MissingDataError, composition, experiment

EQUAL_SHARE_PCT = 100.0 / 25  # every robot's wealth share when wealth is equal (docs/model.md §7)
STAKING, NO_STAKING = "#2ca02c", "#ff7f0e"


def _figure(ncols: int, width: float = 3.6, height: float = 4.2, sharey: bool = True) -> tuple[Figure, list[Axes]]:
    fig = Figure(figsize=(width * ncols, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, ncols, sharey=sharey, squeeze=False)[0]
    return fig, list(axes)


def _panel_title(ax: Axes, letter: str, text: str = "") -> None:
    ax.set_title(f"({letter}) {text}".rstrip(), loc="left", fontsize=10)


def run_count(rows: pd.DataFrame) -> int:
    """How many runs the rows come from (distinct condition and run)."""
    keys = [c for c in ("experiment", "condition", "run") if c in rows.columns]
    return int(len(rows[keys].drop_duplicates())) if keys else 0


def _runs_text(counts) -> str:
    """``32 runs`` or ``30-32 runs`` (per box) from the counts of each box."""
    counts = [int(c) for c in counts if c]
    if not counts:
        return "0 runs"
    lo, hi = min(counts), max(counts)
    return f"{lo} run{'s' if lo != 1 else ''}" if lo == hi else f"{lo}-{hi} runs"


EQUAL_SHARE_LINE = dict(color="grey", linestyle="--", linewidth=0.9)


def _equal_share_handle() -> Line2D:
    return Line2D([], [], **EQUAL_SHARE_LINE, label=f"equal share ({EQUAL_SHARE_PCT:g} %)")


def _no_data(ax: Axes, name: str) -> None:
    ax.text(0.5, 0.5, f"no {name} data\nin the store", ha="center", va="center", transform=ax.transAxes,
            color="grey")
    ax.set_xticks([])


def _box_panels(robots: pd.DataFrame, names: list[str], column: str, scale: float, ylabel: str,
                annotate: Callable[[Axes, pd.DataFrame], str] | None = None,
                extra_handles: list | None = None) -> Figure:
    """One honest-vs-Byzantine box plot per experiment of ``names``, labelled with its swarm and its run
    count; ``annotate`` may draw on the panel and returns text set under it (below the axes, where no
    box or whisker can cross it)."""
    if all(experiment(robots, n).empty for n in names):
        raise MissingDataError(f"none of {', '.join(names)} is in the store")
    fig, axes = _figure(len(names))
    for ax, name in zip(axes, names):
        rows = experiment(robots, name)
        if rows.empty:
            _panel_title(ax, name[-1])
            _no_data(ax, name)
            continue
        n = run_count(rows)
        _panel_title(ax, name[-1], f"{n} run{'s' if n != 1 else ''}, {len(rows)} robots")
        honest_vs_byzantine(ax, rows[column].to_numpy() * scale, rows["honest"].to_numpy())
        ax.set_xlim(-0.7, 0.7)
        ax.set_xticks([])
        label = composition(rows).replace(" + ", "\n+ ")
        if annotate:
            note = annotate(ax, rows)
            label += f"\n{note}" if note else ""
        ax.set_xlabel(label, fontsize=8)
    axes[0].set_ylabel(ylabel)
    fig.legend(handles=legend_handles() + (extra_handles or []), loc="outside lower center",
               ncols=2 + len(extra_handles or []), frameon=False)
    return fig


# ------------------------------------------------------------------------------------------- Fig. 2
def fig2(robots: pd.DataFrame) -> Figure:
    """Items collected per robot after the transitory period: (A) naive, (B) naive + saboteur,
    (C) sceptical, (D) sceptical + scaboteur."""
    fig = _box_panels(robots, ["fig2A", "fig2B", "fig2C", "fig2D"], "items_collected", 1.0,
                      "items collected per robot")
    fig.suptitle("Fig. 2: items collected per robot", fontsize=11)
    return fig


# ---------------------------------------------------------------------------------------- Figs. 3-4
def _annotate_mann_whitney(ax: Axes, rows: pd.DataFrame) -> str:
    """The equal-share line, and the tests as text for under the panel: the run-level test the report
    judges and the paper's robot-level one."""
    ax.axhline(EQUAL_SHARE_PCT, **EQUAL_SHARE_LINE, zorder=0)
    honest = rows["honest"].to_numpy(bool)
    if honest.all() or not honest.any():
        return ""
    mw = stats.mann_whitney(rows.loc[honest, "wealth_share"], rows.loc[~honest, "wealth_share"])
    means = rows.groupby(["run", "honest"])["wealth_share"].mean().unstack().dropna()
    text = f"robot-level Mann-Whitney U, one-sided: p = {mw.pvalue:.2g}"
    if len(means):
        pr = stats.paired(100.0 * (means[True] - means[False]).to_numpy())
        text = f"run-level signed-rank, {pr.n} runs: p = {pr.p:.2g}\n" + text
    return text


def _wealth_share_figure(robots: pd.DataFrame, number: int, title: str) -> Figure:
    names = [f"fig{number}{p}" for p in "ABC"]
    fig = _box_panels(robots, names, "wealth_share", 100.0, "wealth share (%)", _annotate_mann_whitney,
                      [_equal_share_handle()])
    fig.suptitle(f"Fig. {number}: {title}", fontsize=11)
    return fig


def fig3(robots: pd.DataFrame) -> Figure:
    """Wealth share per robot under outlier penalisation, 1, 3 and 5 scaboteurs; one-sided Mann-Whitney
    U p-value (honest > Byzantine) on each panel; dashed line = equal share (4 %)."""
    return _wealth_share_figure(robots, 3, "wealth share, outlier penalisation")


def fig4(robots: pd.DataFrame) -> Figure:
    """As Fig. 3, with staking (0.04 per sale)."""
    return _wealth_share_figure(robots, 4, "wealth share, outlier penalisation with staking")


# ------------------------------------------------------------------------------------------- Fig. 5
def fig5(history: pd.DataFrame, robots: pd.DataFrame | None = None) -> Figure:
    """Average wealth over time of honest robots and scaboteurs, (A) absolute and (B) as a share of the
    swarm's wealth, with 95 % bootstrap bands over runs.  ``robots`` is needed only when the history
    has no ``honest`` column."""
    curves = metrics.wealth_curves(history, robots)
    rows = experiment(history, "fig5")
    if "behaviour" not in rows.columns and robots is not None:
        rows = experiment(robots, "fig5")
    fig, axes = _figure(2, width=5.2, sharey=False)
    for ax, (key, letter, ylabel, scale) in zip(axes, [("wealth", "A", "mean wealth per robot", 1.0),
                                                       ("share", "B", "mean wealth share (%)", 100.0)]):
        for honest, colour in ((True, HONEST), (False, BYZANTINE)):
            if honest not in curves[key]:
                continue
            table = curves[key][honest]
            band = stats.mean_band(table.to_numpy())
            steps = table.columns.to_numpy()
            label = metrics.behaviour_label(rows, honest)
            ax.plot(steps, band.centre * scale, color=colour, label=f"{label} ({len(table)} runs)")
            ax.fill_between(steps, band.low * scale, band.high * scale, color=colour, alpha=0.25,
                            linewidth=0)
        if key == "share":
            ax.axhline(EQUAL_SHARE_PCT, **EQUAL_SHARE_LINE, zorder=0, label=_equal_share_handle().get_label())
        _panel_title(ax, letter)
        ax.set_xlabel("step")
        ax.set_ylabel(ylabel)
    handles, labels = axes[1].get_legend_handles_labels()  # below the panels: no curve can be hidden
    fig.legend(handles, labels, loc="outside lower center", ncols=len(labels), fontsize=8, frameon=False)
    fig.suptitle("Fig. 5: average wealth over time (shades: 95 % CI over runs)", fontsize=11)
    return fig


# ------------------------------------------------------------------------------------------- Fig. 6
def fig6(robots: pd.DataFrame, history: pd.DataFrame | None = None) -> Figure:
    """|odometry drift| against wealth share of honest robots, (A) no Byzantines and (B) five
    scaboteurs; least-squares line with a 95 % bootstrap band, and Pearson r with its 95 % CI.
    Measured after 15 000 steps, as the paper's caption says, when the history recorded that step."""
    history = pd.DataFrame() if history is None else history
    names = ["fig6A", "fig6B"]
    if all(experiment(robots, n).empty for n in names):
        raise MissingDataError("neither fig6A nor fig6B is in the store")
    fig, axes = _figure(2, width=4.6)
    for ax, name in zip(axes, names):
        rows = experiment(robots, name)
        _panel_title(ax, name[-1])
        if rows.empty:
            _no_data(ax, name)
            continue
        honest, when = metrics.drift_and_share(rows, history, name)
        if len(honest) < 3:
            _no_data(ax, name)
            continue
        x = honest["abs_drift"].to_numpy()
        y = honest["wealth_share"].to_numpy() * 100.0
        ax.scatter(x, y, s=6, color=HONEST, alpha=0.35, linewidths=0)
        grid = np.linspace(x.min(), x.max(), 100)
        band = stats.regression_band(x, y, grid)
        ax.plot(grid, band.centre, color="black", linewidth=1.5)
        ax.fill_between(grid, band.low, band.high, color="black", alpha=0.2, linewidth=0)
        c = stats.pearson(x, y)
        n = run_count(rows)
        _panel_title(ax, name[-1], f"{n} run{'s' if n != 1 else ''}, {c.n} honest robots")
        ax.set_xlabel(f"|odometry drift| (deg/step)\n{composition(rows)}\nPearson r = {c.r:.2f}, 95 % CI "
                      f"[{c.low:.2f}, {c.high:.2f}]\nn = {c.n} robots, {when}", fontsize=8)
    axes[0].set_ylabel("wealth share (%), honest robots")
    fig.suptitle("Fig. 6: odometry drift vs wealth share", fontsize=11)
    return fig


# ------------------------------------------------------------------------------------------- Fig. 7
def fig7_tests(runs: pd.DataFrame, byzantines: int, *, alpha: float = stats.ALPHA, margin_fraction: float = 0.10
               ) -> pd.DataFrame:
    """The tests Fig. 7's claims rest on, one row per rotation angle (run-level, ``stats``):

    - 3 Byzantines ("staking significantly higher above Theta"): one-sided Mann-Whitney of staking over
      no staking at each angle above Theta, Holm over those angles, power for a gain of
      ``margin_fraction`` x the no-staking median (the ``fig7B_staking_helps`` row's declaration);
    - 1 Byzantine ("no apparent advantage"): equivalence by TOST within +/- ``margin_fraction`` x the
      no-staking median at every angle, Holm over the angles (the ``fig7A_no_difference`` row's 10 %).
    ``significant`` is the Holm-adjusted verdict; ``hl``/``hl_low``/``hl_high`` the Hodges-Lehmann shift of
    staking over no staking with its 95 % bootstrap interval."""
    panel = runs[runs["byzantines"] == byzantines]
    rows = []
    for a in np.sort(panel["rotation_angle"].unique()):
        if byzantines == 3 and a <= THETA_DEG:
            continue
        at = panel[panel["rotation_angle"] == a]
        x = at.loc[at["market"] == "staking", "throughput"].to_numpy(float)
        y = at.loc[at["market"] == "no_staking", "throughput"].to_numpy(float)
        if len(x) == 0 or len(y) == 0:
            continue
        margin = margin_fraction * float(np.median(y))
        if byzantines == 3:
            c = stats.compare(x, y, declared=margin, alpha=alpha, label=f"{a:g} deg")
            p, e = c.p, c.effect
        else:
            p, lo, _ = stats.tost(x, y, margin, alpha=alpha)
            e = lo.effect
        rows.append({"angle": float(a), "n_staking": len(x), "n_no_staking": len(y), "margin": margin, "p": p,
                     "hl": e.hl, "hl_low": e.hl_low, "hl_high": e.hl_high,
                     "min_p": stats.min_pvalue(len(x), len(y))})
    out = pd.DataFrame(rows, columns=["angle", "n_staking", "n_no_staking", "margin", "p", "hl", "hl_low", "hl_high",
                                      "min_p"])
    out["p_holm"] = stats.holm(out["p"].to_numpy()) if len(out) else []
    out["significant"] = out["p_holm"] < alpha
    out["too_few_runs"] = out["min_p"] * max(len(out), 1) >= alpha  # even the most extreme ordering cannot pass
    return out


def _fig7_rules() -> tuple[float, float, float]:
    """(alpha, 7B's margin fraction, 7A's margin fraction) as the tolerance rows declare them."""
    rules = load_rules()
    b, a = rules["fig7B_staking_helps"], rules["fig7A_no_difference"]
    return (float(b.params.get("alpha", stats.ALPHA)), float(b.params.get("margin_fraction", 0.10)),
            float(a.max) / 100.0 if a.max is not None else 0.10)


def fig7(robots: pd.DataFrame) -> Figure:
    """Items collected by the swarm after the transitory period against the Byzantines' rotation angle,
    with and without staking, (A) one and (B) three Byzantines; dotted line at Theta = 30 deg.  Each
    panel names its runs per box and the test of the paper's claim for it: (B) staking higher at each
    angle above Theta (one-sided Mann-Whitney, Holm; * above the angle when significant), (A) staking
    equivalent to no staking within the 7A row's 10 % (TOST, Holm; = above the angle when shown).
    A market or angle missing from a panel while the others have runs is marked "missing" there."""
    runs = metrics.swarm_throughput(robots)
    alpha, margin_b, margin_a = _fig7_rules()
    fig, axes = _figure(2, width=6.0, height=5.0)
    all_angles = np.sort(runs["rotation_angle"].unique())
    for ax, (letter, byz) in zip(axes, [("A", 1), ("B", 3)]):
        panel = runs[runs["byzantines"] == byz]
        name = f"{byz} Byzantine{'s' if byz > 1 else ''}"
        if panel.empty:
            _panel_title(ax, letter, name)
            _no_data(ax, f"fig7 ({byz} Byzantine)")
            continue
        angles = all_angles
        counts, missing = [], []
        for market, colour, offset in (("no_staking", NO_STAKING, -2.2), ("staking", STAKING, 2.2)):
            sel = panel[panel["market"] == market]
            data = [sel.loc[sel["rotation_angle"] == a, "throughput"].to_numpy() for a in angles]
            counts += [len(d) for d in data]
            missing += [(a + offset, market) for a, d in zip(angles, data) if len(d) == 0]
            draw_boxes(ax, data, angles + offset, colour, width=3.8)
        top = float(panel["throughput"].max())
        ax.set_ylim(0, top * 1.16 if top > 0 else 1.0)
        for x, market in missing:
            ax.text(x, top * 0.5, f"missing: {market.replace('_', ' ')}", rotation=90, ha="center", va="center",
                    fontsize=7, color="#b00000")
        tests = fig7_tests(runs, byz, alpha=alpha, margin_fraction=margin_b if byz == 3 else margin_a)
        mark = "*" if byz == 3 else "="
        for t in tests.itertuples():
            ax.text(t.angle, top * 1.06, mark if t.significant else "ns", ha="center", va="center",
                    fontsize=9 if t.significant else 6)
        shown = int(tests["significant"].sum())
        claim = (f"staking higher at {shown} of {len(tests)} angles > {THETA_DEG:g} deg" if byz == 3 else
                 f"equivalent within ±{100 * margin_a:g} % at {shown} of {len(tests)} angles")
        few = " (n too small)" if len(tests) and tests["too_few_runs"].all() else ""
        miss = f", {len(missing)} box{'es' if len(missing) != 1 else ''} MISSING" if missing else ""
        _panel_title(ax, letter, f"{name}, {_runs_text(counts)} per box{miss}\n{claim}{few}")
        ax.axvline(THETA_DEG, color="grey", linestyle=":", linewidth=1)
        ax.set_xticks(angles, [f"{a:g}" for a in angles], fontsize=8)
        ax.set_xlabel("rotation angle of the Byzantine robots (deg)")
        ax.set_xlim(angles.min() - 6, angles.max() + 6)
    axes[0].set_ylabel("items collected by the swarm\n(after the transitory period)")
    fig.legend(handles=legend_handles({NO_STAKING: "without staking (delayed payment)",
                                       STAKING: "with staking (outlier penalisation, 0.04)"})
               + [Line2D([], [], color="grey", linestyle=":", label=f"Theta = {THETA_DEG:g} deg"),
                  Line2D([], [], linestyle="none", marker="$*$", color="black", markersize=8,
                         label=f"B: staking higher, one-sided Mann-Whitney, Holm p < {alpha:g}"),
                  Line2D([], [], linestyle="none", marker="$=$", color="black", markersize=8,
                         label=f"A: equivalent within ±{100 * margin_a:g} % (TOST, Holm p < {alpha:g})"),
                  Line2D([], [], linestyle="none", marker="$ns$", color="black", markersize=10,
                         label="not shown")],
               loc="outside lower center", ncols=3, frameon=False, fontsize=8)
    fig.suptitle("Fig. 7: collective performance vs rotation angle", fontsize=11)
    return fig


# ------------------------------------------------------------------------------------------ registry
@dataclass(frozen=True)
class FigureSpec:
    """One of the paper's figures: its name, its caption and the function that draws it from the tables."""
    name: str
    caption: str
    draw: Callable[[Frames], Figure]


FIGURES: tuple[FigureSpec, ...] = (
    FigureSpec("fig2", "Items collected per robot: (A) 25 naive, (B) 24 naive + 1 saboteur, (C) 25 sceptical, "
               "(D) 24 sceptical + 1 scaboteur. Blue honest, red Byzantine.", lambda f: fig2(f.robots)),
    FigureSpec("fig3", "Wealth share per robot with outlier penalisation, 1, 3 and 5 scaboteurs; one-sided "
               "Mann-Whitney U p-value (honest > Byzantine) per panel; dashed line = 4 %.", lambda f: fig3(f.robots)),
    FigureSpec("fig4", "As Fig. 3, with staking (0.04 per sale).", lambda f: fig4(f.robots)),
    FigureSpec("fig5", "Average wealth of honest robots and scaboteurs (20 + 5, staking) over time, (A) absolute, "
               "(B) share; shades: 95 % bootstrap CI over runs.", lambda f: fig5(f.history, f.robots)),
    FigureSpec("fig6", "|Odometry drift| vs wealth share of honest robots, (A) 25 sceptical, (B) 20 sceptical + "
               "5 scaboteurs; least-squares line with 95 % bootstrap band, Pearson r with 95 % CI.",
               lambda f: fig6(f.robots, f.history)),
    FigureSpec("fig7", "Items collected by the swarm after the transitory period vs rotation angle, with and "
               "without staking, (A) 1 and (B) 3 Byzantines.", lambda f: fig7(f.robots)),
)


def save(fig: Figure, out: Path, name: str, vector: str = "svg") -> list[Path]:
    """Write ``name.png`` and ``name.svg`` (or ``.pdf``) under ``out`` (``figure_parts``); each whole or not
    at all (the store's atomic writer)."""
    return [write_atomic(out / file, part, keep_suffix=True) for file, part in figure_parts(fig, name, vector)]


def figure_parts(fig: Figure, name: str, vector: str = "svg") -> list[tuple[str, Callable[[Path], None]]]:
    """``fig`` as two parts of a study's ``Report``: ``name.png`` and ``name.svg`` (or ``.pdf``), saved
    without timestamps or random ids, so the same data give the same files."""
    vector_meta = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}[vector]

    def png(path: Path) -> None:
        """The raster, at the reports' resolution, without the software's name (which changes with versions)."""
        with matplotlib.rc_context({"svg.hashsalt": "infomarket"}):
            fig.savefig(path, dpi=150, metadata={"Software": None})

    def drawing(path: Path) -> None:
        """The vector drawing, without its creation date."""
        with matplotlib.rc_context({"svg.hashsalt": "infomarket"}):
            fig.savefig(path, metadata=vector_meta)
    return [(f"{name}.png", png), (f"{name}.{vector}", drawing)]
