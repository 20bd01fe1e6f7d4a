"""Global sensitivity indices of a sampled design (``[sweep.sample]``), computed by SALib.

``run_outputs`` turns the robots table into one value per run and output; ``point_outputs`` averages
the runs of each design point and puts the points in the design's order (what SALib's estimators need);
``analyse`` calls SALib: Sobol' first-order, total (and second-order) indices with bootstrap 95 %
intervals, Morris μ* (with its interval), μ and σ, or RBD-FAST first-order indices for a Latin
hypercube.  Every function takes plain DataFrames and a ``Design``; ``from_store`` reads both from a
results store.  ``write`` saves the table (CSV and Parquet), the figures and ``sensitivity.md``.
"""
from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.sample import BUILTIN_OUTPUTS
from ..runner.design import Design
from .frames import MissingDataError

RUN = ["condition", "run"]
CONF_LEVEL = 0.95
RESAMPLES = 1000
COLUMNS = ["experiment", "output", "method", "index", "parameter", "parameter2", "value", "conf", "low", "high"]
TITLES = {"S1": "first order S1", "ST": "total ST", "S2": "second order S2", "mu_star": "Morris μ*",
          "mu": "Morris μ", "sigma": "Morris σ"}


@dataclass
class Sensitivity:
    """The indices of one design: ``table`` (long: one row per output, index and parameter)."""

    design: Design
    table: pd.DataFrame
    points: pd.DataFrame                       # the per-point outputs the indices were computed from
    files: list[Path] = field(default_factory=list)


def _rows(robots: pd.DataFrame, who: str) -> pd.DataFrame:
    if who == "all":
        return robots
    return robots[robots["honest"] == (who == "honest")]


def run_outputs(robots: pd.DataFrame, design: Design) -> pd.DataFrame:
    """One row per run of the design: ``point``, ``condition``, ``run`` and one column per output."""
    rows = robots
    if "experiment" in rows.columns:
        rows = rows[rows["experiment"] == design.experiment]
    need = {"point", "condition", "run", "honest", "items_collected", "wealth_share"}
    missing = sorted(need - set(rows.columns))
    if rows.empty or missing:
        raise MissingDataError(f"{design.experiment}: no runs of the design in the tables"
                               + (f" (missing columns {', '.join(missing)})" if missing and not rows.empty else ""))
    g = rows.groupby(RUN, observed=True)
    out = g["point"].first().astype(np.int64).to_frame()
    for name in design.outputs:
        if name == "items":
            out[name] = g["items_collected"].sum().astype(float)
        elif name in ("share_gap", "byzantine_share"):
            honest = rows[rows["honest"]].groupby(RUN, observed=True)["wealth_share"]
            byz = rows[~rows["honest"]].groupby(RUN, observed=True)["wealth_share"]
            if name == "share_gap":
                out[name] = 100.0 * (honest.mean() - byz.mean())
            else:
                out[name] = 100.0 * byz.sum()
                out[name] = out[name].fillna(0.0)
        else:
            spec = design.custom[name]
            if spec["column"] not in rows.columns:
                raise MissingDataError(f"output {name}: the robots table has no column {spec['column']!r}; "
                                       f"it has {', '.join(rows.columns)}")
            values = pd.to_numeric(_rows(rows, spec["robots"])[spec["column"]], errors="coerce")
            out[name] = values.groupby([rows["condition"], rows["run"]], observed=True).agg(spec["stat"])
    return out.reset_index()


def point_outputs(runs: pd.DataFrame, design: Design) -> pd.DataFrame:
    """The mean over runs of every output at each point, indexed 0 .. points - 1 in the design's order;
    refuses a design with points not yet run (resume the sweep) or outputs that are undefined."""
    per_point = runs.groupby("point")[design.outputs].mean()
    missing = sorted(set(range(design.points)) - set(per_point.index))
    if missing:
        raise MissingDataError(f"{design.experiment}: {len(missing)} of the design's {design.points} points "
                               f"have no completed run (the first: point {missing[0]}); resume the sweep "
                               f"(`infomarket sweep` with the same --out) before analysing")
    per_point = per_point.reindex(range(design.points))
    bad = [o for o in design.outputs if per_point[o].isna().any()]
    if bad:
        first = int(per_point.index[per_point[bad[0]].isna()][0])
        raise MissingDataError(f"{design.experiment}: output {bad[0]} is undefined at point {first} (e.g. "
                               f"no robot of the kind it averages); the indices need a value at every point")
    return per_point


def _long(design: Design, output: str, index: str, values, conf=None) -> list[dict]:
    z = []
    for j, p in enumerate(design.names):
        v = float(values[j])
        c = float(conf[j]) if conf is not None else np.nan
        z.append({"experiment": design.experiment, "output": output, "method": design.method, "index": index,
                  "parameter": p, "parameter2": "", "value": v, "conf": c, "low": v - c, "high": v + c})
    return z


def analyse(design: Design, points: pd.DataFrame, *, seed: int | None = None) -> pd.DataFrame:
    """SALib's indices of every output of ``points`` (from ``point_outputs``), as one long table.

    ``conf`` is the half-width of the 95 % bootstrap interval (``low``/``high`` its ends); ``seed``
    (default: the design's) makes the bootstrap repeatable."""
    import warnings

    from SALib.analyze import morris, rbd_fast, sobol

    seed = design.seed if seed is None else seed
    problem = design.problem()
    rows: list[dict] = []
    for output in design.outputs:
        Y = points[output].to_numpy(dtype=float)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            if design.method == "sobol":
                S = sobol.analyze(problem, Y, calc_second_order=design.second_order, num_resamples=RESAMPLES,
                                  conf_level=CONF_LEVEL, seed=seed)
                rows += _long(design, output, "S1", S["S1"], S["S1_conf"])
                rows += _long(design, output, "ST", S["ST"], S["ST_conf"])
                if design.second_order:
                    d = len(design.names)
                    for a in range(d):
                        for b in range(a + 1, d):
                            v, c = float(S["S2"][a, b]), float(S["S2_conf"][a, b])
                            rows.append({"experiment": design.experiment, "output": output, "method": "sobol",
                                         "index": "S2", "parameter": design.names[a],
                                         "parameter2": design.names[b], "value": v, "conf": c,
                                         "low": v - c, "high": v + c})
            elif design.method == "morris":
                S = morris.analyze(problem, design.X, Y, num_resamples=RESAMPLES, conf_level=CONF_LEVEL,
                                   num_levels=design.levels, seed=seed)
                rows += _long(design, output, "mu_star", S["mu_star"], S["mu_star_conf"])
                rows += _long(design, output, "mu", S["mu"])
                rows += _long(design, output, "sigma", S["sigma"])
            else:
                S = rbd_fast.analyze(problem, design.X, Y, num_resamples=RESAMPLES, conf_level=CONF_LEVEL,
                                     seed=seed)
                rows += _long(design, output, "S1", S["S1"], S["S1_conf"])
    return pd.DataFrame(rows, columns=COLUMNS)


def sensitivity(robots: pd.DataFrame, design: Design, *, seed: int | None = None) -> Sensitivity:
    """The indices from a robots table (a store's, or a notebook's DataFrame) and its design."""
    points = point_outputs(run_outputs(robots, design), design)
    return Sensitivity(design, analyse(design, points, seed=seed), points)


def from_store(store, experiment: str | None = None) -> Sensitivity:
    """The indices of the design kept in ``store`` (the only one, or ``experiment``'s)."""
    from ..runner import design as designs
    from ..store import Store, StoreError

    store = Store(store) if not isinstance(store, Store) else store
    if not store.exists():
        raise StoreError(f"{store.root}: not an infomarket results store (no store.json)")
    names = designs.designs(store.root)
    if not names:
        raise MissingDataError(f"{store.root}: holds no sampled design (sweep an experiment with a "
                               f"[sweep.sample] section into it)")
    if experiment is None:
        if len(names) > 1:
            raise StoreError(f"{store.root}: holds designs of {', '.join(names)}; name one with --experiment")
        experiment = names[0]
    elif experiment not in names:
        raise StoreError(f"{store.root}: holds no design of {experiment!r}; it holds {', '.join(names)}")
    return sensitivity(store.robots(), designs.load(store.root, experiment))


# ------------------------------------------------------------------------------------ robustness
DRIVES = 0.1  # a parameter drives an output when its total index (Sobol') is at least this


def drivers(s: Sensitivity, threshold: float = DRIVES) -> dict[str, list[str]]:
    """The parameters whose total index (Sobol'), μ* share (Morris) or S1 (RBD-FAST) is ≥ ``threshold``."""
    t = s.table
    kind = {"sobol": "ST", "morris": "mu_star", "lhs": "S1"}[s.design.method]
    out = {}
    for output in s.design.outputs:
        rows = t[(t.output == output) & (t["index"] == kind)]
        values = rows.value / rows.value.sum() if kind == "mu_star" and rows.value.sum() > 0 else rows.value
        out[output] = rows.parameter[values >= threshold].tolist()
    return out


def robustness(s: Sensitivity, runs: pd.DataFrame, at: dict[str, float], *, bins: int = 10,
               tolerance: float = 0.1) -> pd.DataFrame:
    """Whether the point ``at`` (a value per parameter) sits in a flat region of each output.

    For each output and each parameter that drives it, the runs are cut into ``bins`` equal-width bins
    of that parameter (one bin per value for an integer parameter); the medians of the runs in ``at``'s bin and in the adjacent bins are compared
    with the output's 5-95 % range over the design (robust when the difference is below ``tolerance``
    of it), with a two-sided Mann-Whitney U test on the two sets of runs.  ``runs``: ``run_outputs``."""
    from scipy.stats import mannwhitneyu

    d = s.design
    unknown = sorted(set(at) - set(d.names))
    if unknown:
        raise MissingDataError(f"--at: unknown parameter {unknown[0]!r}; the design has {', '.join(d.names)}")
    values = d.frame().set_index("point")
    rows = []
    for output, params in drivers(s).items():
        y = runs[output].to_numpy(dtype=float)
        lo, hi = np.nanpercentile(y, [5, 95])
        for p in params:
            if p not in at:
                continue
            j = d.names.index(p)
            if d.integer[j]:  # an integer key: one bin per value
                edges = np.arange(d.low[j] - 0.5, d.high[j] + 1.0)
            else:
                edges = np.linspace(d.low[j], d.high[j], bins + 1)
            nb = len(edges) - 1
            x = values.loc[runs["point"].to_numpy(), p].to_numpy(dtype=float)
            which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, nb - 1)
            home = int(np.clip(np.searchsorted(edges, at[p], side="right") - 1, 0, nb - 1))
            near = [b for b in (home - 1, home + 1) if 0 <= b < nb]
            a, b = y[which == home], y[np.isin(which, near)]
            diff = float(np.median(b) - np.median(a)) if len(a) and len(b) else np.nan
            pval = float(mannwhitneyu(a, b, alternative="two-sided").pvalue) if len(a) and len(b) else np.nan
            rows.append({"output": output, "parameter": p, "at": at[p],
                         "bin": f"[{edges[home]:g}, {edges[home + 1]:g})", "runs_in_bin": len(a),
                         "runs_adjacent": len(b), "median_in_bin": float(np.median(a)) if len(a) else np.nan,
                         "median_adjacent": float(np.median(b)) if len(b) else np.nan, "difference": diff,
                         "range_5_95": float(hi - lo), "relative": abs(diff) / (hi - lo) if hi > lo else np.nan,
                         "mann_whitney_p": pval,
                         "robust": bool(abs(diff) < tolerance * (hi - lo)) if np.isfinite(diff) else False,
                         "positive_in_bin": float(np.mean(a > 0)) if len(a) else np.nan})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------------------- figures
def _bars(s: Sensitivity):
    from matplotlib.figure import Figure

    t, d = s.table, s.design
    kinds = {"sobol": ["S1", "ST"], "morris": ["mu_star", "sigma"], "lhs": ["S1"]}[d.method]
    outs = d.outputs
    fig = Figure(figsize=(1.0 + 0.9 * len(d.names), 2.8 * len(outs)), layout="constrained")
    axes = fig.subplots(len(outs), 1, squeeze=False)[:, 0]
    x = np.arange(len(d.names))
    width = 0.8 / len(kinds)
    for ax, output in zip(axes, outs):
        for k, kind in enumerate(kinds):
            rows = t[(t.output == output) & (t["index"] == kind)].set_index("parameter").reindex(d.names)
            err = rows["conf"].to_numpy() if rows["conf"].notna().any() else None
            ax.bar(x + (k - (len(kinds) - 1) / 2) * width, rows["value"], width, yerr=err, capsize=3,
                   label=TITLES[kind])
        ax.set_xticks(x, d.names, rotation=20, ha="right")
        ax.axhline(0, color="black", linewidth=0.6)
        ax.set_title(f"{d.experiment}: {output}", fontsize=10)
        ax.set_ylabel("index" if d.method != "morris" else "effect (output units)")
        ax.legend(fontsize=8)
    fig.suptitle(f"{d.method} design, {d.points} points, 95 % bootstrap intervals", fontsize=9)
    return fig


def _heatmap(s: Sensitivity):
    from matplotlib.figure import Figure

    d, t = s.design, s.table
    n = len(d.names)
    fig = Figure(figsize=(4.2 * len(d.outputs), 4.0), layout="constrained")
    axes = fig.subplots(1, len(d.outputs), squeeze=False)[0]
    for ax, output in zip(axes, d.outputs):
        m = np.full((n, n), np.nan)
        for r in t[(t.output == output) & (t["index"] == "S2")].itertuples():
            a, b = d.names.index(r.parameter), d.names.index(r.parameter2)
            m[a, b] = m[b, a] = r.value
        top = max(0.05, float(np.nanmax(np.abs(m))) if np.isfinite(m).any() else 0.05)
        im = ax.imshow(m, cmap="RdBu_r", vmin=-top, vmax=top)  # estimates can be negative: show them so
        ax.set_xticks(range(n), d.names, rotation=45, ha="right", fontsize=7)
        ax.set_yticks(range(n), d.names, fontsize=7)
        ax.set_title(f"{output}: S2", fontsize=10)
        fig.colorbar(im, ax=ax, shrink=0.8)
    return fig


# ---------------------------------------------------------------------------------------- writing
def _fmt(v: float) -> str:
    return "" if not np.isfinite(v) else f"{v:.3f}"


def summary_table(s: Sensitivity) -> pd.DataFrame:
    """One row per output and parameter: the main indices side by side (what the report shows)."""
    t = s.table[s.table["index"] != "S2"]
    wide = t.pivot_table(index=["output", "parameter"], columns="index", values=["value", "conf"],
                         sort=False)
    rows = []
    for (output, p), r in wide.iterrows():
        row = {"output": output, "parameter": p}
        for kind in dict.fromkeys(t["index"]):
            v, c = r[("value", kind)], r.get(("conf", kind), np.nan)
            row[TITLES[kind]] = _fmt(v) + (f" ± {_fmt(c)}" if np.isfinite(c) else "")
        rows.append(row)
    return pd.DataFrame(rows)


def markdown(s: Sensitivity, files: list[str]) -> str:
    from .report import _md_table

    d = s.design
    lines = [f"## Global sensitivity: {d.experiment}", "",
             f"{d.method} design of {d.points} points ({d.samples} base samples, seed {d.seed}, SALib "
             f"{d.salib}) over {len(d.names)} parameters; indices with 95 % bootstrap intervals "
             f"({RESAMPLES} resamples).", ""]
    lines += [_md_table(pd.DataFrame({"parameter": d.names, "key": d.keys,
                                      "range": [f"[{lo:g}, {hi:g}]" for lo, hi in zip(d.low, d.high)]})), ""]
    lines += [_md_table(summary_table(s)), ""]
    lines += [f"![{f}]({f})" for f in files if f.endswith(".png")]
    return "\n".join(lines) + "\n"


def html_section(s: Sensitivity, files: list[str]) -> str:
    from .report import _html_table

    d = s.design
    parts = [f"<h2>Global sensitivity: {html.escape(d.experiment)}</h2>",
             f"<p>{d.method} design of {d.points} points ({d.samples} base samples, seed {d.seed}, SALib "
             f"{html.escape(d.salib)}); 95 % bootstrap intervals.</p>", _html_table(summary_table(s))]
    parts += [f"<p><img src='{html.escape(f)}' alt='{html.escape(f)}'></p>" for f in files if f.endswith(".png")]
    return "\n".join(parts)


def write(s: Sensitivity, out: str | Path, *, vector: str = "svg") -> list[Path]:
    """``sensitivity.csv`` / ``.parquet`` (the long table), the bar chart (and the S2 heat map of a
    second-order Sobol' design) as PNG and ``vector``, and ``sensitivity.md``; returns the files."""
    from .figures import save

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = f"sensitivity-{s.design.experiment}"
    files = [out / f"{stem}.csv", out / f"{stem}.parquet"]
    s.table.to_csv(files[0], index=False)
    s.table.to_parquet(files[1], index=False)
    figs = save(_bars(s), out, f"{stem}-indices", vector)
    if s.design.method == "sobol" and s.design.second_order:
        figs += save(_heatmap(s), out, f"{stem}-S2", vector)
    md = out / f"{stem}.md"
    md.write_text(markdown(s, [p.name for p in figs]), encoding="utf-8")
    s.files = files + figs + [md]
    return s.files


def report_section(store, out: Path, vector: str = "svg", echo=lambda line: None) -> list[tuple[str, str]]:
    """(markdown, html) of every design in ``store``, figures written into ``out``; [] when it has none
    or when a design is not complete yet (with a note through ``echo``)."""
    from ..runner import design as designs

    sections = []
    for name in designs.designs(store.root):
        try:
            s = from_store(store, name)
        except MissingDataError as exc:
            echo(f"sensitivity of {name}: skipped ({exc})")
            continue
        files = write(s, out, vector=vector)
        names = [p.name for p in files if p.suffix in (".png", f".{vector}")]
        sections.append((markdown(s, names), html_section(s, names)))
        echo(f"sensitivity of {name}: wrote {', '.join(p.name for p in files)}")
    return sections


__all__ = ["BUILTIN_OUTPUTS", "Sensitivity", "analyse", "from_store", "point_outputs", "run_outputs",
           "sensitivity", "write"]
