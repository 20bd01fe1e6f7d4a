"""A declared study: a questions file, the stores it is answered from, and the files it writes.

Every study of the package (the paper's headline rows and its open questions in ``tolerances.toml``, the
terrain, sensitivity and chain studies) goes the same way: read its declaration file, answer each declared
question from a store's runs, and write the verdicts as markdown (and CSV/JSON) with a figure.  What is
common lives here: reading the file, how its declarations relate to a store's record (``declared``), the
study's record of amendments and deviations (printed in every report it writes), tables in markdown and
HTML, the ``Verdict`` every question is answered with (its answer, the numbers and comparisons it rests
on, what qualifies it), and the command-line plumbing (``--out`` checked before anything runs; files written at the
end).
The studies keep only what is theirs: the per-run values, the rule of each question, the figure.

A declaration file records its history in two arrays of tables, beside its questions:

- ``[[amendments]]``: a change to the study (its rules, run plan or conditions), with ``date``, ``seen``
  (what results had been seen when it was made), ``what`` changed and ``why``;
- ``[[deviations]]``: a way the study was run that differs from what it declared (a half not run, a run
  stopped early), with the same fields.

They are notes about the declarations, not declarations: a store's lock check leaves them out.
"""
from __future__ import annotations

import html
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..cliargs import UsageError, writable_dir
from ..errors import ConfigError
from . import declared
from . import stats as st
from .declared import NOTES, Lock, check, status_of, summary

HERE = Path(__file__).parent
#: a declared question's answers: decided by its rule, or why the store cannot decide it yet
YES, NO, INCONCLUSIVE = st.YES, st.NO, st.INCONCLUSIVE
NO_DATA, NOT_RUN, PENDING = "no data", "not run", "pending"
#: the arrays of a declaration file that record its history (see the module's docstring)
RECORDS = NOTES
_FIELDS = ("date", "seen", "what", "why")


@dataclass(frozen=True)
class Record:
    """One amendment or deviation of a declared study."""

    kind: str        # "amendment" / "deviation"
    date: str        # when it was made (ISO date, with a UTC time where the order of events matters)
    seen: str        # which results had been seen when it was made
    what: str        # what changed (or what was done instead of the declared plan)
    why: str
    questions: tuple[str, ...] = ()  # the questions it touches (none: the whole study)

    def markdown(self) -> str:
        """The record as one Markdown list item: kind, date, scope, when it was made, what changed and why."""
        scope = f" ({', '.join(self.questions)})" if self.questions else ""
        return (f"- **{self.kind.capitalize()}, {self.date}**{scope}, {self.seen}: {self.what} "
                f"*Why:* {self.why}")


@dataclass(frozen=True)
class Declaration:
    """A study's declaration file, read once: its questions, its other tables, its record."""

    name: str        # the name a store records it under (``store.declarations.FILES``)
    path: Path
    data: dict

    @classmethod
    def read(cls, path: str | Path, name: str | None = None) -> Declaration:
        """Read a declaration file, checking its amendment and deviation records at once.

        Args:
            path: the TOML file.
            name: the name a store records it under (default: the file's name).

        Raises:
            ConfigError: the file cannot be read or parsed, or a record is malformed.
        """
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise ConfigError(f"{path}: cannot read the study's declarations ({exc})") from None
        decl = cls(name or path.name, path, data)
        decl.records()  # a malformed record is refused here, not in the middle of a report
        return decl

    @property
    def questions(self) -> dict:
        """The declared questions by id (empty if the file declares none)."""
        return self.data.get("questions", {})

    def records(self) -> list[Record]:
        """Every amendment and deviation, in the file's order (amendments first)."""
        out = []
        for table in RECORDS:
            for i, entry in enumerate(self.data.get(table, [])):
                missing = [k for k in _FIELDS if not str(entry.get(k, "")).strip()]
                if missing:
                    raise ConfigError(f"{self.path}: {table}[{i}] lacks {', '.join(missing)}")
                unknown = sorted(set(entry) - {*_FIELDS, "questions"})
                if unknown:
                    raise ConfigError(f"{self.path}: {table}[{i}]: unknown key {unknown[0]!r}; allowed: "
                                      f"{', '.join((*_FIELDS, 'questions'))}")
                out.append(Record(table[:-1], str(entry["date"]), entry["seen"], entry["what"], entry["why"],
                                  tuple(entry.get("questions", ()))))
        return out

    def record_markdown(self) -> list[str]:
        """The report's section on the study's history: every amendment and deviation of the file."""
        records = self.records()
        lines = [f"## Amendments and deviations ({self.name})", ""]
        if not records:
            return lines + [f"{self.name} records none: the study ran as declared.", ""]
        return lines + [r.markdown() for r in records] + [""]

    def record_html(self) -> str:
        """The amendments and deviations as an HTML heading and list (``record_markdown`` rendered)."""
        md = self.record_markdown()
        items = "".join(f"<li>{html.escape(line[2:].replace('**', '').replace('*', ''))}</li>"
                        for line in md[2:] if line.startswith("- "))
        return f"<h2>{html.escape(md[0][3:])}</h2>" + (f"<ul>{items}</ul>" if items else f"<p>{html.escape(md[2])}</p>")

    # ------------------------------------------------------------------ against a store's record
    def locks(self, recorded: dict | None) -> list[Lock]:
        """Each declaration against the store's record, read from the file the store records under this
        name (``declared.FILES``; this file for one no store records)."""
        return check(recorded, {self.name: declared.FILES.get(self.name, self.path)})

    def lock_summary(self, recorded: dict | None, prefix: str = "") -> str:
        """One line: how many of the declarations (those starting with ``prefix``) were fixed before the store's
        first run."""
        return summary(self.locks(recorded), self.name, prefix)

    def question_status(self, recorded: dict | None) -> set[str]:
        """The set of statuses of the questions against the store's record (declared, edited, added or not
        recorded)."""
        locks = self.locks(recorded)
        return {status_of(locks, self.name, f"questions.{q}") for q in self.questions}


def packaged(name: str) -> Declaration:
    """One of the analysis package's declaration files, by file name (``chain_questions.toml``)."""
    return Declaration.read(HERE / name)


# ------------------------------------------------------------------------------------------ verdicts
@dataclass
class Verdict:
    """One declared question's answer with what it rests on: every study answers with these, so a
    report, a table or a test reads the answer, its numbers and its qualifying note the same way
    whatever the study.  ``details`` grows while a study adds descriptive lines to an answer."""

    answer: str                 # YES / NO / INCONCLUSIVE, or NO_DATA / NOT_RUN / PENDING, or a study's own
    statistics: str = ""        # the numbers the answer rests on, as the report prints them
    comparisons: tuple = ()     # the ``stats.Comparison`` objects it was decided from
    note: str = ""              # what qualifies it (``stats.N_TOO_SMALL``, conditions not run, ...)
    details: list[str] = field(default_factory=list)  # one line per condition or descriptive result
    n: str = ""                 # runs per group, as printed
    effect: str = ""            # the effect it rests on, with its interval, as printed
    value: object = None        # the answer's value where the question asks for one (a breaking point)

    @property
    def shown(self) -> str:
        """The answer as printed: ``inconclusive (n too small)`` when a note qualifies it."""
        return st.shown(self.answer, self.note)


def by_power(met: bool, power: float, target: float = st.POWER) -> str:
    """A one-sided rule's answer: yes when it is met; no when it is not and its test had the power to
    meet it; inconclusive otherwise (the runs could not have decided it)."""
    if met:
        return YES
    return NO if power >= target else INCONCLUSIVE


# ------------------------------------------------------------------------------------------ tables
def md_cell(text) -> str:
    r"""A value as one Markdown table cell: pipes escaped, line breaks flattened.

    Example:
        >>> from infomarket.analysis.study import md_cell
        >>> md_cell("a|b\nc")
        'a\\|b c'
    """
    return str(text).replace("|", "\\|").replace("\n", " ")


def md_table(df: pd.DataFrame) -> str:
    """A DataFrame as a Markdown table (header, rule, one line per row).

    Example:
        >>> import pandas as pd
        >>> from infomarket.analysis.study import md_table
        >>> print(md_table(pd.DataFrame({"n": [1, 2], "answer": ["yes", "no"]})))
        | n | answer |
        |---|---|
        | 1 | yes |
        | 2 | no |
    """
    lines = ["| " + " | ".join(md_cell(c) for c in df.columns) + " |",
             "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(md_cell(v) for v in row) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines)


def html_table(df: pd.DataFrame, verdicts: bool = False) -> str:
    """A table; with ``verdicts``, each row classed by its last cell (pass / fail / inconclusive ...)."""
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in df.columns)
    body = []
    for row in df.itertuples(index=False):
        cls = ""
        if verdicts:
            cls = f' class="{str(row[-1]).split(" (")[0].replace(" ", "")}"'
        body.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(str(v))}</td>" for v in row) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


# ------------------------------------------------------------------------------------------ files
def out_dir(path: str | Path) -> Path:
    """``--out``: refused before anything runs when it exists and is not a folder."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    return out


def write(out: Path, stem: str, markdown: str, *, table: pd.DataFrame | None = None,
          figure: Callable[[Path], object] | None = None, extra: Iterable[tuple[str, str]] = ()) -> list[Path]:
    """``stem.md`` (and ``stem.csv`` of ``table``, ``stem.png`` by ``figure(path)``, each ``(name, text)`` of
    ``extra``) in ``out``, created when missing: the study's files, written once its answers exist."""
    out = writable_dir(out)
    files = [out / f"{stem}.md"]
    files[0].write_text(markdown, encoding="utf-8")
    if table is not None:
        files.append(out / f"{stem}.csv")
        table.to_csv(files[-1], index=False)
    for name, text in extra:
        files.append(out / name)
        files[-1].write_text(text, encoding="utf-8")
    if figure is not None:
        files.append(out / f"{stem}.png")
        figure(files[-1])
    return files
