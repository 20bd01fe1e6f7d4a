"""The chain study's figure (``chain-study.png``), drawn from its answers (``analysis.chain_study``)."""
from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib
import numpy as np

from .chain_study import FIG7, FIG7_SWEEP, PAPER, SWEEP, Answers, _sel, axis_values, declaration

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # after the backend is chosen


def figure(a: Answers, path: Path, decl: dict | None = None) -> None:
    """chain-study.png: the wealth share and Fig. 7's items along each swept knob (rows 1-2), the named
    settings' boxes (row 3) and the partition's answers."""
    decl = decl or declaration()
    runs = a.runs
    fig, axes = plt.subplots(3, 3, figsize=(15, 12.5), constrained_layout=True)
    xlabels = {"period": "block period (steps)", "loss": "message loss probability",
               "gas": "gas price (a reveal's gas / the stake)"}
    for j, axis in enumerate(("period", "loss", "gas")):
        pts = axis_values(decl, axis)
        xs = np.arange(len(pts))
        ax = axes[0, j]
        for payment, colour, mk in (("outlier", "tab:orange", "o"), ("staking", "tab:blue", "s")):
            med, lo, hi, ns = [], [], [], []
            for _, label in pts:
                x = (_sel(runs, PAPER, chain=label, payment=payment, byzantines=5) if label == "toychain"
                     else _sel(runs, SWEEP, chain=label, payment=payment))
                ns.append(len(x))
                med.append(np.median(x) if len(x) else np.nan)
                lo.append(np.percentile(x, 25) if len(x) else np.nan)
                hi.append(np.percentile(x, 75) if len(x) else np.nan)
            med, lo, hi = map(np.asarray, (med, lo, hi))
            name = "Fig. 3C (no stake)" if payment == "outlier" else "Fig. 4C (staking)"
            ax.errorbar(xs, med, yerr=[med - lo, hi - med], color=colour, marker=mk, capsize=3, label=f"{name}: chain")
            ref = _sel(runs, PAPER, chain="instant", payment=payment, byzantines=5)
            if len(ref):
                ax.axhline(np.median(ref), color=colour, ls="--", lw=1, label=f"{name}: instant ledger (n={len(ref)})")
        ax.axhline(20.0, color="grey", ls=":", lw=1, label="equal share (5 of 25)")
        ax.set_xticks(xs, [f"{v:g}" for v, _ in pts])
        ax.set_xlabel(xlabels[axis])
        ax.set_ylabel("Byzantines' wealth share, % (median, IQR)")
        shown = a.table.set_index("question").loc[f"breaks_{axis}", "answer"].split(" (")[0]
        ax.set_title(f"Figs. 3C/4C vs {axis}; the result breaks: {shown}", fontsize=10)
        ax.text(0.01, 0.99, f"runs per point: {min(ns)}-{max(ns)}", transform=ax.transAxes, va="top", fontsize=8)
        ax.legend(fontsize=7, loc="best")
        ax = axes[1, j]
        for market, colour, mk in (("staking", "tab:blue", "s"), ("no_staking", "tab:red", "^")):
            med, lo, hi, ns = [], [], [], []
            for _, label in pts:
                x = (_sel(runs, FIG7, "items", chain=label, market=market, rotation_angle=90.0) if label == "toychain"
                     else _sel(runs, FIG7_SWEEP, "items", chain=label, market=market))
                ns.append(len(x))
                med.append(np.median(x) if len(x) else np.nan)
                lo.append(np.percentile(x, 25) if len(x) else np.nan)
                hi.append(np.percentile(x, 75) if len(x) else np.nan)
            med, lo, hi = map(np.asarray, (med, lo, hi))
            ax.errorbar(xs, med, yerr=[med - lo, hi - med], color=colour, marker=mk, capsize=3,
                        label=f"{market.replace('_', ' ')}: chain")
            ref = _sel(runs, FIG7, "items", chain="instant", market=market, rotation_angle=90.0)
            if len(ref):
                ax.axhline(np.median(ref), color=colour, ls="--", lw=1,
                           label=f"{market.replace('_', ' ')}: instant (n={len(ref)})")
        ax.set_xticks(xs, [f"{v:g}" for v, _ in pts])
        ax.set_xlabel(xlabels[axis])
        ax.set_ylabel("swarm items, last 10 000 steps (median, IQR)")
        ax.set_title(f"Fig. 7, 3 Byzantines at 90 deg vs {axis}", fontsize=10)
        ax.text(0.01, 0.02, f"runs per point: {min(ns)}-{max(ns)}" + ("" if max(ns or [0]) else " (not run)"),
                transform=ax.transAxes, fontsize=8)
        ax.legend(fontsize=7, loc="best")
    # the named settings
    ax = axes[2, 0]
    settings = ("instant", "toychain", "geth_argos")
    conds = [(p, k) for p in ("outlier", "staking") for k in (1, 3, 5)]
    width = 0.26
    _boxes_by_setting(ax, settings, width,
                      lambda s: [_sel(runs, PAPER, chain=s, payment=p, byzantines=k) for p, k in conds])
    ax.set_xticks(np.arange(len(conds)), [f"{'3' if p == 'outlier' else '4'}{'ABC'[(k - 1) // 2]}" for p, k in conds])
    ax.set_xlabel("paper condition (Fig. 3: no stake, Fig. 4: staking; A/B/C: 1/3/5 Byzantines)")
    ax.set_ylabel("Byzantines' wealth share, %")
    ax.set_title(f"Figs. 3-4: toychain {a.verdicts['wealth_toychain'].answer}, geth-argos "
                 f"{a.verdicts['wealth_geth_argos'].answer}", fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[2, 1]
    conds7 = [(m, ang) for ang in (45.0, 90.0) for m in ("staking", "no_staking")]
    _boxes_by_setting(ax, settings, width,
                      lambda s: [_sel(runs, FIG7, "items", chain=s, market=m, rotation_angle=ang) for m, ang in conds7])
    ax.set_xticks(np.arange(len(conds7)), [f"{m.replace('_', ' ')}\n{ang:g} deg" for m, ang in conds7])
    ax.set_ylabel("swarm items, last 10 000 steps")
    ax.set_title(f"Fig. 7: toychain {a.verdicts['fig7_toychain'].answer}, geth-argos "
                 f"{a.verdicts['fig7_geth_argos'].answer}", fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[2, 2]
    pf, pr = a.verdicts["partition_forks"], a.verdicts["partition_rich"]
    ax.set_axis_off()
    ax.text(0.02, 0.95, "Partition (food side | nest side)", fontsize=11, va="top", transform=ax.transAxes)
    ax.text(0.02, 0.80, f"forks that undo payments: {pf.answer}\n{textwrap.fill(pf.note, 50)}\n\n"
                        f"changes who gets rich: {pr.answer}\n{textwrap.fill(pr.note, 50)}",
            fontsize=9, va="top", transform=ax.transAxes)
    fig.suptitle("The paper's result on the robots' own chain (chain_questions.toml)", fontsize=12)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _boxes_by_setting(ax, settings, width: float, data_of) -> None:
    """One box per condition for each chain setting, the settings side by side around each condition's
    tick (``data_of(setting)``: the conditions' values, in tick order), each setting in its colour."""
    for i, s in enumerate(settings):
        data = data_of(s)
        pos = np.arange(len(data)) + (i - 1) * width
        ok = [d if len(d) else np.array([np.nan]) for d in data]
        bp = ax.boxplot(ok, positions=pos, widths=width * 0.9, patch_artist=True, showfliers=False)
        for b in bp["boxes"]:
            b.set_facecolor(("lightgrey", "tab:green", "tab:purple")[i])
        ax.plot([], [], "s", color=("lightgrey", "tab:green", "tab:purple")[i],
                label=f"{s} (n={max(len(d) for d in data)})")
