"""The sensitivity study's report: its declared questions (``sensitivity_questions.toml``) answered from a
global design (and, for robustness, a local one), the figures, the markdown/HTML section and the files.
The indices themselves are ``analysis.sensitivity``'s."""
from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pandas as pd

from ..runner import design as designs
from ..cliargs import UsageError
from ..store import Store
from .declared import status_of
from .figures import figure_parts
from .frames import MissingDataError
from . import sensitivity as sens  # module-level knobs (PAWN_PERMUTATIONS) read when drawing
from .sensitivity import TITLES, Sensitivity, floor_of, from_store, local_robustness, morris_noise
from .study import INCONCLUSIVE, NO, YES, Declaration, Report, Study, html_table, md_table, packaged

DECLARATION = packaged("sensitivity_questions.toml")
QUESTIONS = DECLARATION.path


# ------------------------------------------------------------------------------------- questions
def load_questions(path: Path = QUESTIONS) -> dict:
    """The declared sensitivity questions (``sensitivity_questions.toml``, or the file ``path``) as parsed TOML."""
    return DECLARATION.data if Path(path) == QUESTIONS else Declaration.read(path).data


def answers(s: Sensitivity, questions: dict | None = None, local: tuple[pd.DataFrame, pd.DataFrame] | None = None,
            locks: list | None = None) -> pd.DataFrame:
    """The declared questions (``sensitivity_questions.toml``) answered from a global design and,
    for robustness, a local one: one row per question and output with the answer and its numbers.
    A design of another size than the declared one says so; the precision question is answered only
    at the declared size."""

    q = (questions or load_questions())["questions"]
    d, t = s.design, s.table
    declared = q["design"]
    lo_r, hi_r = s.runs_per_point
    at_size = d.samples == declared["samples"] and lo_r == hi_r == declared["runs"]
    size = ("" if at_size else f"NOTE: answered at {d.samples} base samples x {lo_r}"
            f"{'' if lo_r == hi_r else f'-{hi_r}'} runs, not the {declared['samples']} x {declared['runs']} declared. ")
    rows = []

    def lock(qid: str) -> str:
        return status_of(locks, "sensitivity_questions.toml", f"questions.{qid}") if locks is not None else ""

    def get(output: str, index: str) -> pd.DataFrame:
        return t[(t.output == output) & (t["index"] == index)].set_index("parameter").reindex(d.names)

    if d.method == "sobol":
        for output in d.outputs:
            st, s1 = get(output, "ST"), get(output, "S1")
            f, flo, fhi = floor_of(s, output)
            pw, pn = get(output, "PAWN"), get(output, "PAWN_null")
            pawn_text = ("; PAWN above its no-effect level: " + (", ".join(
                f"{p} {pw.value[p]:.2f}" for p in pw.value.sort_values(ascending=False).index
                if pw.value[p] > pn.value[p]) or "none") if pw.value.notna().any() else "")
            if np.isnan(f):
                rows.append(["drivers", output, INCONCLUSIVE, size + "one run per point: the seed-noise floor "
                             "is unknown, so total indices cannot be told from noise", lock("drivers")])
            else:
                p = q["drivers"]
                excess = st.value - f
                drive = [n for n in d.names if excess[n] >= p["min_excess"] and st.low[n] > fhi]
                top = s1.value.idxmax()
                dominant = (top if s1.value[top] >= p["dominant_s1"] and s1.low[top] > 0 else None)
                text = (f"floor {f:.2f} [{flo:.2f}, {fhi:.2f}]; S_T - floor: "
                        + ", ".join(f"{n} {excess[n]:+.2f}" for n in excess.sort_values(ascending=False).index)
                        + f"; largest S_1: {top} {s1.value[top]:.2f} [{s1.low[top]:.2f}, {s1.high[top]:.2f}]"
                        + (" (dominant)" if dominant else " (none dominant)") + pawn_text)
                rows.append(["drivers", output, ", ".join(drive) or "none", size + text, lock("drivers")])
                inter = [n for n in d.names if st.value[n] - s1.value[n] - f >= q["interactions"]["min_excess"]]
                rows.append(["interactions", output, ", ".join(inter) or "none", size + "S_T - S_1 - floor: "
                             + ", ".join(f"{n} {st.value[n] - s1.value[n] - f:+.2f}" for n in d.names),
                             lock("interactions")])
        if s.floor is not None and len(s.floor):
            for r in s.floor.itertuples():
                rows.append(["noise_floor", r.output, f"{100 * r.run_share:.0f} % of single-run variance",
                             size + f"run level {r.run_share:.2f} [{r.run_share_low:.2f}, {r.run_share_high:.2f}]; "
                             f"floor of the means of {r.runs_per_point} runs {r.floor:.2f} [{r.floor_low:.2f}, "
                             f"{r.floor_high:.2f}]", lock("noise_floor")])
        s1 = t[t["index"] == "S1"]
        widths = (s1.high - s1.low).groupby(s1.output).max()
        text = "largest full width of a first-order interval: " + ", ".join(f"{o} {w:.3f}" for o, w in widths.items())
        if at_size:
            ok = bool((widths < q["precision"]["max_width"]).all())
            rows.append(["precision", "all", YES if ok else NO, text, lock("precision")])
        else:
            rows.append(["precision", "all", f"not answered ({d.samples} x {lo_r} is not the declared size)",
                         size + text, lock("precision")])
    if local is not None:
        verdicts, params = local
        for r in verdicts.itertuples():
            moved = params[(params.output == r.output) & params.moves].parameter.tolist() if len(params) else []
            rows.append(["robust", r.output, r.robust,
                         f"spread caused by the parameters in the box {r.spread:.3g} [{r.spread_low:.3g}, "
                         f"{r.spread_high:.3g}] vs tolerance {r.tolerance:.3g} (5 % of the global 5-95 % range "
                         f"{r.range_5_95:.3g}); {r.runs} runs, median {r.median:.3g}, positive in "
                         f"{100 * r.positive:.0f} %; parameters whose Morris mu* is above seed noise: "
                         f"{', '.join(moved) or 'none'}", lock("robust")])
    return pd.DataFrame(rows, columns=["question", "output", "answer", "statistics", "declared"])


# --------------------------------------------------------------------------------------- figures
HATCH = {"S1": "", "ST": "//", "mu_star": "", "sigma": "//", "PAWN": ""}


def _bars(s: Sensitivity):
    """Per output: the indices with their intervals (legend beside the axes, hiding no bar), the
    seed-noise floor of the total indices as a dashed line with its interval shaded, and (Sobol' or
    hypercube designs with PAWN) the PAWN indices with the level a parameter without effect reaches."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t, d = s.table, s.design
    kinds = {"sobol": ["S1", "ST"], "morris": ["mu_star", "sigma"], "lhs": ["S1"]}[d.method]
    has_pawn = bool((t["index"] == "PAWN").any())
    outs = d.outputs
    ncols = 2 if has_pawn else 1
    fig = Figure(figsize=(3.6 + 1.0 * len(d.names) * ncols, 3.2 * len(outs)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(outs), ncols, squeeze=False)
    x = np.arange(len(d.names))
    width = 0.8 / len(kinds)
    for row, output in enumerate(outs):
        ax = axes[row, 0]
        for k, kind in enumerate(kinds):
            rows = t[(t.output == output) & (t["index"] == kind)].set_index("parameter").reindex(d.names)
            err = rows["conf"].to_numpy() if rows["conf"].notna().any() else None
            ax.bar(x + (k - (len(kinds) - 1) / 2) * width, rows["value"], width, yerr=err, capsize=3,
                   label=TITLES[kind], hatch=HATCH.get(kind, ""), edgecolor="black", linewidth=0.5)
        f, flo, fhi = floor_of(s, output)
        noise_mu = morris_noise(s, output)
        if np.isfinite(noise_mu):
            ax.axhline(noise_mu, color="black", linestyle="--", linewidth=1.2,
                       label=f"μ* of seed noise alone ({noise_mu:.3g})")
        if d.method == "sobol" and np.isfinite(f):
            ax.axhspan(flo, fhi, color="grey", alpha=0.25, linewidth=0, label="floor's 95 % interval")
            ax.axhline(f, color="black", linestyle="--", linewidth=1.2,
                       label=f"seed-noise floor of S_T ({f:.2f})")
        ax.set_xticks(x, d.names, rotation=40, ha="right", rotation_mode="anchor", fontsize=8)
        ax.axhline(0, color="black", linewidth=0.6)
        ax.set_title(f"{output}: {TITLES[kinds[0]].split()[0]}{' / total' if d.method == 'sobol' else ''}, "
                     f"{s.size()}", fontsize=9, loc="left")
        ax.set_ylabel("index" if d.method != "morris" else "effect (output units)")
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        if has_pawn:
            ax = axes[row, 1]
            rows = t[(t.output == output) & (t["index"] == "PAWN")].set_index("parameter").reindex(d.names)
            null = t[(t.output == output) & (t["index"] == "PAWN_null")].set_index("parameter").reindex(d.names)
            ax.bar(x, rows["value"], 0.6, color="#9467bd", edgecolor="black", linewidth=0.5, label=TITLES["PAWN"])
            ax.plot(x, null["value"], linestyle="none", marker="_", markersize=14, markeredgewidth=2,
                    color="black",
                    label=f"no effect: 95th percentile,\n{sens.PAWN_PERMUTATIONS} shuffles of the output")
            ax.set_xticks(x, d.names, rotation=40, ha="right", rotation_mode="anchor", fontsize=8)
            ax.set_ylim(0, max(0.1, float(np.nanmax(rows["value"].to_numpy())) * 1.15,
                               float(np.nanmax(null["value"].to_numpy())) * 1.15))
            ax.set_title(f"{output}: PAWN, {s.size()}", fontsize=9, loc="left")
            ax.set_ylabel("PAWN index")
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.suptitle(f"{d.experiment}: {d.method} design, {d.samples} base samples; 95 % bootstrap intervals",
                 fontsize=10)
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
    """One row per output and parameter: the main indices side by side (what the report shows); PAWN
    with its percentile interval, the others ± the interval's half-width."""
    t = s.table[s.table["index"].isin([k for k in TITLES if k != "S2"])]
    rows = []
    for (output, p), g in t.groupby(["output", "parameter"], sort=False):
        row = {"output": output, "parameter": p}
        for r in g.itertuples():
            if r.index == "PAWN_null":
                row[TITLES["PAWN"]] = row.get(TITLES["PAWN"], "") + f" (no effect: {_fmt(r.value)})"
            elif r.index == "PAWN":
                row[TITLES[r.index]] = _fmt(r.value) + row.get(TITLES["PAWN"], "")
            else:
                row[TITLES[r.index]] = _fmt(r.value) + (f" ± {_fmt(r.conf)}" if np.isfinite(r.conf) else "")
        rows.append(row)
    return pd.DataFrame(rows)


def floor_table(s: Sensitivity) -> pd.DataFrame:
    """The seed-noise shares with their intervals, one row per output (empty for one run per point)."""
    if s.floor is None or s.floor.empty:
        return pd.DataFrame()
    return pd.DataFrame({"output": s.floor.output,
                         "runs per point": s.floor.runs_per_point,
                         "seed noise, share of single-run variance": [
                             f"{r.run_share:.3f} [{r.run_share_low:.3f}, {r.run_share_high:.3f}]"
                             for r in s.floor.itertuples()],
                         "floor of S_T (share of the point means' variance)": [
                             f"{r.floor:.3f} [{r.floor_low:.3f}, {r.floor_high:.3f}]" for r in s.floor.itertuples()]})


def _intro(s: Sensitivity) -> str:
    d = s.design
    lo, hi = s.runs_per_point
    text = (f"{d.method} design, {d.samples} base samples, {s.size()} (seed {d.seed}, SALib {d.salib}) over "
            f"{len(d.names)} parameters; the indices see the mean of each point's runs; 95 % bootstrap intervals "
            f"({sens.RESAMPLES} resamples); PAWN beside a permutation test ({sens.PAWN_PERMUTATIONS} shuffles).")
    if hi < 2:
        text += (" Every point ran once, so seed noise sits under every total index and its share cannot be "
                 "estimated: set `runs` >= 2 in the experiment.")
    return text


def markdown(s: Sensitivity, files: list[str], answers_table: pd.DataFrame | None = None) -> str:
    """The global-sensitivity section as Markdown: the parameters and ranges, the seed-noise floor, the indices,
    the answers and figures."""
    d = s.design
    lines = [f"## Global sensitivity: {d.experiment}", "", _intro(s), ""]
    lines += [md_table(pd.DataFrame({"parameter": d.names, "key": d.keys,
                                      "range": [f"[{lo:g}, {hi:g}]" for lo, hi in zip(d.low, d.high)]})), ""]
    ft = floor_table(s)
    if len(ft):
        lines += ["Seed noise (from the replicates of every point):", "", md_table(ft), ""]
    lines += [md_table(summary_table(s)), ""]
    if answers_table is not None and len(answers_table):
        lines += ["Declared questions (`src/infomarket/analysis/sensitivity_questions.toml`):", "",
                  md_table(answers_table), ""]
        lines += [line.replace("## ", "### ", 1) for line in DECLARATION.record_markdown()]
    lines += [f"![{f}]({f})" for f in files if f.endswith(".png")]
    return "\n".join(lines) + "\n"


def html_section(s: Sensitivity, files: list[str], answers_table: pd.DataFrame | None = None) -> str:
    """The global-sensitivity section as HTML, the same content as ``markdown``."""
    d = s.design
    parts = [f"<h2>Global sensitivity: {html.escape(d.experiment)}</h2>", f"<p>{html.escape(_intro(s))}</p>"]
    ft = floor_table(s)
    if len(ft):
        parts.append(html_table(ft))
    parts.append(html_table(summary_table(s)))
    if answers_table is not None and len(answers_table):
        parts += [html_table(answers_table), DECLARATION.record_html().replace("h2>", "h3>")]
    parts += [f"<p><img src='{html.escape(f)}' alt='{html.escape(f)}'></p>" for f in files if f.endswith(".png")]
    return "\n".join(parts)


def declared_answers(s: Sensitivity, store=None, local: tuple[pd.DataFrame, pd.DataFrame] | None = None
                     ) -> pd.DataFrame | None:
    """``answers`` for the design the questions file declares (None for another experiment), with each
    question's lock status against ``store``'s record (``analysis.declared``)."""

    questions = load_questions()
    if s.design.experiment != questions["questions"]["design"]["experiment"]:
        return None
    locks = DECLARATION.locks(store.declarations()) if store is not None else None
    return answers(s, questions, local, locks)


def stem(experiment: str) -> str:
    """The files' name: the experiment's, prefixed with ``sensitivity-`` unless it says so already
    (``sensitivity``, ``sensitivity_local``; not ``sensitivity-sensitivity``)."""
    return experiment if experiment.startswith("sensitivity") else f"sensitivity-{experiment}"


def report(s: Sensitivity, *, vector: str = "svg", answers_table: pd.DataFrame | None = None) -> Report:
    """``STEM.csv`` / ``.parquet`` (the long table, the noise floor and PAWN included), the bar chart
    (and the S2 heat map of a second-order Sobol' design) as PNG and ``vector``, and ``STEM.md``
    (``stem``: ``sensitivity-NAME``, or NAME when it starts with "sensitivity"), as a ``Report``."""
    name = stem(s.design.experiment)
    figs = figure_parts(_bars(s), f"{name}-indices", vector)
    if s.design.method == "sobol" and s.design.second_order:
        figs += figure_parts(_heatmap(s), f"{name}-S2", vector)
    return Report([(f"{name}.csv", s.table), (f"{name}.parquet", s.table), *figs,
                   (f"{name}.md", markdown(s, [f for f, _ in figs], answers_table))])


def write(s: Sensitivity, out: str | Path, *, vector: str = "svg",
          answers_table: pd.DataFrame | None = None) -> list[Path]:
    """``report(s, ...)`` written into ``out`` (created when missing); returns the files (kept in
    ``s.files``)."""
    s.files = report(s, vector=vector, answers_table=answers_table).write(out)
    return s.files


class SensitivityStudy(Study):
    """The sensitivity study: the indices of a store's sampled design (``experiment``: which, when the store
    holds several), its declared questions answered (``sensitivity_questions.toml``), and with ``local``,
    a store of a replicated local design, whether that point is robust (``STEM-robustness.csv``)."""

    declaration = DECLARATION

    def __init__(self, experiment: str | None = None, vector: str = "svg", local: str | None = None) -> None:
        self.experiment, self.vector, self.local = experiment, vector, local
        self.indices: Sensitivity | None = None
        self.robustness: tuple[pd.DataFrame, pd.DataFrame] | None = None
        self.answers: pd.DataFrame | None = None

    def answer(self, store) -> Report:
        """The indices, tables, figures and ``STEM.md`` of the design in ``store`` (a store's folder).

        Raises:
            UsageError: a store holds no complete sampled design (the store named).
        """
        try:
            s = from_store(store, self.experiment)
        except MissingDataError as exc:
            raise UsageError(_named(store, exc)) from None
        local = None
        if self.local:
            try:
                local = local_robustness(from_store(self.local), s.points)
            except MissingDataError as exc:
                raise UsageError(f"--local {_named(self.local, exc)}") from None
        table = declared_answers(s, Store(store), local)
        parts = report(s, vector=self.vector, answers_table=table).parts
        if local is not None:
            parts.append((f"{stem(s.design.experiment)}-robustness.csv", local[0]))
            if len(local[1]):
                parts.append((f"{stem(s.design.experiment)}-local-mu-star.csv", local[1]))
        self.indices, self.robustness, self.answers = s, local, table
        return Report(parts)


def _named(path: str, exc: Exception) -> str:
    """``PATH: message``, with the path once: a message that already starts with it is left as it is."""
    text = str(exc)
    bare = str(path).rstrip("/")
    return text if bare and text.startswith(bare) else f"{path}: {text}"


def report_section(store, parts: list, vector: str = "svg", echo=lambda line: None) -> list[tuple[str, str]]:
    """(markdown, html) of every design in ``store``, its files added to ``parts`` (a study ``Report``'s);
    [] when it has none or when a design is not complete yet (with a note through ``echo``)."""

    sections = []
    for name in designs.designs(store.root):
        try:
            s = from_store(store, name)
        except MissingDataError as exc:
            echo(f"sensitivity of {name}: skipped ({exc})")
            continue
        table = declared_answers(s, store)
        files = report(s, vector=vector, answers_table=table).parts
        parts += files
        names = [f for f, _ in files if f.endswith((".png", f".{vector}"))]
        sections.append((markdown(s, names, table), html_section(s, names, table)))
        echo(f"sensitivity of {name}: wrote {', '.join(f for f, _ in files)}")
    return sections
