"""``report.md`` and ``report.html``: every figure, the "paper vs this store" table, and provenance.

``build_report`` draws and saves each figure (skipping, with a one-line note, those whose data the
store lacks), computes the headline table and provenance once, and writes both documents from the
same ``Report`` so they never disagree.
"""
from __future__ import annotations

import contextlib
import html
import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..store import Store
from . import future
from .completeness import gaps
from . import study
from .figures import FIGURES, figure_parts
from .frames import Frames, MissingDataError
from .headline import DECLARATION as TOLERANCES, FAIL, INCOMPLETE, INCONCLUSIVE, NO_DATA, PASS, headline_table
from .stats import N_TOO_SMALL, shown
from .provenance import Provenance, collect_provenance
from .sensitivity_report import report_section
from .study import html_table, md_table

TABLE_COLUMNS = {"figure": "figure", "claim": "claim", "paper": "paper", "store": "this store",
                 "tolerance": "tolerance", "verdict": "verdict"}


@dataclass
class FigureResult:
    """One figure of the report: the files drawn, or why it was skipped, and a warning if drawn from an incomplete
    design."""
    name: str
    caption: str
    files: list[Path] = field(default_factory=list)  # empty when skipped
    note: str = ""                                    # why it was skipped
    warning: str = ""                                 # drawn from an incomplete design: what is missing


@dataclass
class Report:
    """What ``build_report`` wrote and judged: the figures, the headline table with its verdicts, provenance and
    extra sections."""
    source: str
    figures: list[FigureResult]
    table: pd.DataFrame
    provenance: Provenance
    files: list[Path] = field(default_factory=list)
    future: future.Section | None = None  # the open-questions section, for stores with the future sweep
    sections: list[tuple[str, str]] = field(default_factory=list)  # (markdown, html), e.g. sensitivity
    lock: str = ""  # were the rows' rules declared before the store's first run (analysis.declared)
    gaps: list[str] = field(default_factory=list)  # incomplete experiments (analysis.completeness)
    lengths: list[str] = field(default_factory=list)  # experiments run at another length than the paper's

    def counts(self) -> dict[str, int]:
        """How many headline rows passed, failed, were inconclusive or had no data."""
        return {v: int((self.table["verdict"] == v).sum()) for v in (PASS, FAIL, INCONCLUSIVE, NO_DATA)}


def build_report(source, out: str | Path, *, vector: str = "svg", label: str | None = None,
                 echo: Callable[[str], None] = lambda line: None, store: Store | None = None) -> Report:
    """Write the figures, ``report.md`` and ``report.html`` under ``out``; ``echo`` gets one line per step.

    ``source`` is anything ``Frames.of`` reads; ``label`` names it in the report (default: its path).
    ``store`` (or ``source`` when it is a store): its sampled designs get a global-sensitivity section."""
    out = Path(out)
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    # drawn into a staging folder inside ``out`` and moved in once every file is written: a full disk or a
    # stop half-way leaves ``out`` as it was (an older report whole), never a part of a new set beside it
    staging = Path(tempfile.mkdtemp(prefix=".report-", suffix=".part", dir=out))
    try:
        report, parts = _draw(source, vector, label or _label(source), echo, store)  # HeadlineStudy's answer
        study.Report(parts).write(staging)
        for path in sorted(staging.iterdir()):
            os.replace(path, out / path.name)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        if created:
            with contextlib.suppress(OSError):  # only if still empty
                out.rmdir()
        raise
    staging.rmdir()
    report.files = [out / p.name for p in report.files]
    for r in report.figures:
        r.files = [out / p.name for p in r.files]
    if report.future is not None:
        report.future.figures = [(n, c, [out / p.name for p in files], note)
                                 for n, c, files, note in report.future.figures]
    echo(f"wrote {', '.join(str(p) for p in report.files)}")
    return report


class HeadlineStudy(study.Study):
    """The paper's headline rows and open questions (``tolerances.toml``) answered from a store (or anything
    ``Frames.of`` reads): every figure, ``report.md`` and ``report.html``, with a sensitivity section for
    each sampled design of ``store`` (or of the source, when it is a store).  ``report`` keeps what it
    judged once ``answer`` has run."""

    declaration = TOLERANCES

    def __init__(self, vector: str = "svg", label: str | None = None,
                 echo: Callable[[str], None] = lambda line: None, store: Store | None = None) -> None:
        self.vector, self.label, self.echo, self.store = vector, label, echo, store
        self.report: Report | None = None

    def answer(self, store) -> study.Report:
        """Every figure drawn, the headline table, the open questions and ``report.md`` / ``report.html`` of
        ``store``, as the files they are written to."""
        self.report, parts = _draw(store, self.vector, self.label or _label(store), self.echo, self.store)
        return study.Report(parts)


def _draw(source, vector: str, label: str, echo: Callable[[str], None], store: Store | None
          ) -> tuple[Report, list]:
    """``HeadlineStudy.answer``'s work: what it judged, and its files as a study ``Report``'s parts."""
    frames = Frames.of(source)
    incomplete = gaps(frames.runs)
    for gap in incomplete.values():
        echo(f"WARNING: {gap.describe()}")
    results: list[FigureResult] = []
    parts: list = []
    for spec in FIGURES:
        try:
            fig = spec.draw(frames)
        except MissingDataError as exc:
            results.append(FigureResult(spec.name, spec.caption, note=str(exc)))
            echo(f"{spec.name}: skipped ({exc})")
            continue
        drawn = figure_parts(fig, spec.name, vector)
        parts += drawn
        files = [Path(name) for name, _ in drawn]
        warning = " ".join(g.describe() for name, g in incomplete.items() if name.startswith(spec.name))
        results.append(FigureResult(spec.name, spec.caption, files, warning=warning))
        echo(f"{spec.name}: wrote {', '.join(p.name for p in files)}" + (" (INCOMPLETE design)" if warning else ""))
    table = headline_table(frames)
    report = Report(label, results, table, collect_provenance(frames, label))
    report.gaps = [g.describe() for g in incomplete.values()]
    report.lengths = length_notes(frames.runs)
    for note in report.lengths:
        echo(f"WARNING: {note}")
    report.lock = TOLERANCES.lock_summary(frames.meta.get("declarations") if frames.meta else None, "rows.")
    report.future = future.section(frames, parts, vector, echo)
    store = store if store is not None else (Store(source) if isinstance(source, (str, Path)) else
                                             source if isinstance(source, Store) else None)
    if store is not None:
        report.sections = report_section(store, parts, vector, echo)
    echo(f"paper vs this store: {_counts_text(report)}")
    for name, text in (("report.md", to_markdown(report)), ("report.html", to_html(report))):
        parts.append((name, text))
        report.files.append(Path(name))
    return report, parts


def length_notes(runs: pd.DataFrame) -> list[str]:
    """One line per shipped experiment whose runs in the store are not as long as the experiment declares
    (the paper's length): its rows compare numbers of runs of two lengths, which the page must say."""
    if runs.empty or "steps" not in runs.columns or "experiment" not in runs.columns:
        return []
    # with the report: the loader is not needed otherwise
    from ..config.load import load_experiment, shipped_experiments

    shipped, out = shipped_experiments(), []
    for name, group in runs.groupby("experiment", sort=True):
        if name not in shipped:
            continue
        declared = load_experiment(name).steps
        have = sorted({int(s) for s in group["steps"].dropna()})
        if have and have != [declared]:
            out.append(f"{name}: runs of {' and '.join(f'{s:,}' for s in have)} steps, judged against numbers for runs "
                       f"of {declared:,} steps (the paper's, the experiment's declared length); counts that grow "
                       f"with the run's length (items, "
                       f"wealth) are not comparable, so read its rows and figures as a look, not a check")
    return out


def _label(source) -> str:
    """How the report names its data: the store's path, or "tables" for DataFrames."""
    if isinstance(source, Store):
        return str(source.root)
    return str(source) if isinstance(source, (str, Path)) else "tables"


# ------------------------------------------------------------------------------------------ markdown
def _counts_text(report: Report) -> str:
    c = report.counts()
    notes = report.table["note"] if "note" in report.table else pd.Series(dtype=str)
    why = [f"{int((notes == n).sum())} {n}" for n in (N_TOO_SMALL, INCOMPLETE) if (notes == n).any()]
    return (f"{c[PASS]} pass, {c[FAIL]} fail, {c[INCONCLUSIVE]} inconclusive"
            + (f" ({', '.join(why)})" if why else "") + f", {c[NO_DATA]} no data")


def _shown_table(report: Report) -> pd.DataFrame:
    """The table as printed: each verdict with its note (``inconclusive (n too small)``)."""
    t = report.table.copy()
    if "note" in t:
        t["verdict"] = [shown(v, n) for v, n in zip(t["verdict"], t["note"])]
    return t[list(TABLE_COLUMNS)].rename(columns=TABLE_COLUMNS)


def _summary(report: Report) -> str:
    text = (f"{_counts_text(report)}, of {len(report.table)} rows (inconclusive: the store's runs cannot "
            f"decide them).")
    return text + (f" Declarations: {report.lock}." if report.lock else "")


def to_markdown(report: Report) -> str:
    """The report as ``report.md``: run lengths and incomplete designs first, then the figures, the paper
    against this store (the headline table) and provenance."""
    md = [f"# Paper figures from {report.source}", "",
          "Figures and headline numbers of *An Information Market for Social Navigation in Robots*, "
          "recomputed from this results store. Tolerances: `src/infomarket/analysis/tolerances.toml` "
          "(declared before any result was seen; rows marked REVISED there were changed after the full paper "
          "sweep: see the amendments at the end).", ""]
    if report.lengths:
        md += ["## Run lengths", "", "These experiments were run at another length than the paper's:", ""] + \
            [f"- **{n}**" for n in report.lengths] + [""]
    if report.gaps:
        md += ["## Incomplete designs", "", "The figures and rows that use these experiments are drawn from part of "
               "their design; their rows are inconclusive.", ""] + [f"- {g}" for g in report.gaps] + [""]
    md += ["## Figures", ""]
    for r in report.figures:
        md.append(f"### {r.name.replace('fig', 'Fig. ')}")
        md.append("")
        md.append(r.caption)
        md.append("")
        if r.warning:
            md += [f"**{r.warning}**", ""]
        if r.files:
            md.append(f"![{r.name}]({r.files[0].name})")
            md.append("")
            md.append(f"Vector: [{r.files[1].name}]({r.files[1].name})")
        else:
            md.append(f"*Skipped: {r.note}.*")
        md.append("")
    md += ["## Paper vs this store", "", _summary(report), "",
           md_table(_shown_table(report)), ""]
    if report.future is not None:
        md += future.to_markdown(report.future)
    md += ["## Provenance", ""]
    md += [f"- {k}: {v}" for k, v in report.provenance.facts.items()]
    if not report.provenance.experiments.empty:
        md += ["", md_table(report.provenance.experiments)]
    for section, _ in report.sections:
        md += ["", section]
    md += ["", *TOLERANCES.record_markdown()]
    return "\n".join(md) + "\n"


# ---------------------------------------------------------------------------------------------- html
CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
img{max-width:100%;border:1px solid #ddd}table{border-collapse:collapse;font-size:90%;margin:1em 0}
td,th{border:1px solid #ccc;padding:4px 8px;text-align:left;vertical-align:top}th{background:#f3f3f3}
.pass{background:#e3f5e1}.fail{background:#fbe0e0}.nodata{background:#f0f0f0;color:#666}
.inconclusive{background:#fff6d6}
.note{color:#666;font-style:italic}"""


def to_html(report: Report) -> str:
    """The report as a self-contained ``report.html`` page, the same content as ``to_markdown``."""
    e = html.escape
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Paper figures from {e(report.source)}"
             f"</title><style>{CSS}</style></head><body>",
             f"<h1>Paper figures from {e(report.source)}</h1>",
             "<p>Figures and headline numbers of <i>An Information Market for Social Navigation in Robots</i>, "
             "recomputed from this results store. Tolerances: <code>src/infomarket/analysis/tolerances.toml"
             "</code> (declared before any result was seen; rows marked REVISED there were changed after the full "
             "paper sweep: see the amendments at the end).</p>", "<h2>Figures</h2>"]
    if report.lengths:
        parts += ["<h2>Run lengths</h2><p>These experiments were run at another length than the paper's:</p><ul>"] \
            + [f"<li><b>{e(n)}</b></li>" for n in report.lengths] + ["</ul>"]
    if report.gaps:
        parts += ["<h2>Incomplete designs</h2><ul>"] + [f"<li>{e(g)}</li>" for g in report.gaps] + ["</ul>"]
    for r in report.figures:
        parts.append(f"<h3>{e(r.name.replace('fig', 'Fig. '))}</h3><p>{e(r.caption)}</p>")
        if r.warning:
            parts.append(f"<p><b>{e(r.warning)}</b></p>")
        if r.files:
            png, vec = (p.name for p in r.files)
            parts.append(f"<p><a href='{e(vec)}'><img src='{e(png)}' alt='{e(r.name)}'></a></p>")
        else:
            parts.append(f"<p class='note'>Skipped: {e(r.note)}.</p>")
    parts += ["<h2>Paper vs this store</h2>", f"<p>{e(_summary(report))}</p>",
              html_table(_shown_table(report), verdicts=True)]
    if report.future is not None:
        parts += future.to_html(report.future)
    parts.append("<h2>Provenance</h2><ul>")
    parts += [f"<li>{e(k)}: {e(v)}</li>" for k, v in report.provenance.facts.items()]
    parts.append("</ul>")
    if not report.provenance.experiments.empty:
        parts.append(html_table(report.provenance.experiments))
    parts += [section for _, section in report.sections]
    parts.append(TOLERANCES.record_html())
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"
