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
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import pandas as pd

from ..cliargs import UsageError, writable_dir
from ..errors import ArgumentError, ConfigError
from ..store.files import write_atomic, write_parquet_atomic, write_text_atomic
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
S = TypeVar("S")


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


# ------------------------------------------------------------------------------------------ settings
#: a rule of ``settings``' ``checks``: the key it is reported under, whether the settings keep it, what is expected
Check = tuple[str, Callable[[Any], bool], str]


def settings(cls: type[S], table: dict, overrides: dict | None = None, source: str = "settings", *,
             whole: dict[str, int] | None = None, flags: Iterable[str] = (),
             numbers: Iterable[tuple[str, float, float]] = (), checks: Iterable[Check] = ()) -> S:
    """A study's settings: the dataclass ``cls`` from its declaration's ``table`` with ``overrides`` (the
    command line's options; None values ignored) over it, each value checked.  Every study's settings are
    read here, and a bad one is refused as an experiment file's bad key is (``config.messages``): one
    message from ``source``, one line per problem naming the key, what is expected and the value given,
    whether it came from the file or an option.

    Args:
        cls: the study's settings dataclass (its fields are the keys allowed).
        table: the declaration file's table of settings.
        overrides: settings given on the command line (None: not given).
        source: where the values come from, the start of every error message.
        whole: key -> the least whole number allowed.
        flags: keys that take true or false.
        numbers: (key, low, high): a number in (low, high].
        checks: (key, ok, expected): a rule of the study's own (``ok(settings)`` false: ``key`` is refused
            with ``expected``), for what the kinds above cannot say (a list's shape, one key bounded by another).

    Raises:
        UsageError: an unknown key (the allowed ones named), or values of the wrong kind or out of range
            (every one of them named).

    Example:
        >>> from dataclasses import dataclass
        >>> from infomarket.analysis.study import settings
        >>> @dataclass(frozen=True)
        ... class Plan:
        ...     runs: int = 8
        >>> settings(Plan, {"runs": 16}, {"runs": None}, whole={"runs": 2})
        Plan(runs=16)
        >>> settings(Plan, {"run": 16})
        Traceback (most recent call last):
        ...
        infomarket.errors.UsageError: settings: invalid settings
          run: unknown key; allowed keys here: runs
    """
    known = list(cls.__dataclass_fields__)  # type: ignore[attr-defined]
    given = {**table, **{k: v for k, v in (overrides or {}).items() if v is not None}}
    unknown = [k for k in given if k not in known]
    if unknown:
        raise UsageError(_invalid(source, [f"{k}: unknown key; allowed keys here: {', '.join(known)}"
                                           for k in unknown]))
    s = cls(**given)
    problems: list[tuple[str, str]] = []
    for k, least in (whole or {}).items():
        v = getattr(s, k)
        if isinstance(v, bool) or not isinstance(v, int) or v < least:
            problems.append((k, f"a whole number of at least {least} is expected"))
    problems += [(k, "true or false is expected") for k in flags if not isinstance(getattr(s, k), bool)]
    for k, lo, hi in numbers:
        v = getattr(s, k)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo < v <= hi:
            problems.append((k, f"a number in ({lo:g}, {hi:g}] is expected"))
    problems += [(k, expected) for k, ok, expected in checks if not ok(s)]
    if problems:  # in the fields' order, each key once (its first rule)
        first = {k: what for k, what in reversed(problems)}
        raise UsageError(_invalid(source, [f"{k}: {first[k]} (got {_shown(getattr(s, k))})"
                                           for k in known if k in first]))
    return s


def _invalid(source: str, lines: list[str]) -> str:
    """A settings error as ``config.messages`` writes an experiment's: the source, then a line per problem."""
    return f"{source}: invalid settings\n  " + "\n  ".join(lines)


def _shown(value: object, limit: int = 80) -> str:
    """A value as an error message quotes it: its repr, cut to ``limit`` characters."""
    text = repr(list(value) if isinstance(value, tuple) else value)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


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
def out_dir(path: str | Path | None, command: str = "", holds: str = "the store and the report") -> Path:
    """``--out``, the one check every study's command makes of it before anything runs.

    Args:
        path: the option's value (None: not given).
        command: the command that needs it, named when it is missing (a command whose parser requires
            ``--out`` never passes None).
        holds: what the folder will hold, named when the value is blank.

    Raises:
        UsageError: it is missing, blank (``Path("")`` would be the current folder), or exists and is not
            a folder.
    """
    if path is None:
        raise UsageError(f"{command} needs --out FOLDER ({holds} go there)")
    if not str(path).strip():
        raise UsageError(f"--out {str(path)!r}: give a folder for {holds}")
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    return out


def refuse_declared_seed(seed: int, declared: int, reductions: list[str]) -> None:
    """``--seed``: a study's declared seed keys its confirmation seeds, which no run may touch before the
    study's own, so any run that is not the whole declared study (a pilot, a reduced study, some of its
    cells: ``reductions`` says how) must take another seed.  The whole study may still be made in several
    invocations: it resumes from its store, every invocation the whole study."""
    if reductions and seed == declared:
        raise UsageError(seed_refusal(seed, reductions))


def seed_refusal(seed: int, reductions: list[str], most: int = 160) -> str:
    """The refusal in one line of at most ``most`` characters: the seed, then what differs from the declared
    study by name (an option, without its values; "2 of 8 cells"), as many as fit and how many more.  Why
    the seed is kept is the docstring's and the docs' to say, not the error line's."""
    names = list(dict.fromkeys(_difference(r) for r in reductions))
    head = f"--seed {seed} is the declared study's own; this run differs in "
    tail = ": give another --seed"
    shown = len(names)
    while shown > 1 and len(_listed(head, names, shown, tail)) > most:
        shown -= 1
    line = _listed(head, names, shown, tail)
    return line if len(line) <= most else line[:most - len(tail) - 1] + "…" + tail


def _difference(reduction: str) -> str:
    """A difference by its name: ``--steps 400 (declared 15000)`` -> ``--steps``; other kinds cut to 24
    characters."""
    if reduction.startswith("--"):
        return reduction.split()[0]
    return reduction if len(reduction) <= 24 else reduction[:23] + "…"


def _listed(head: str, names: list[str], shown: int, tail: str) -> str:
    more = len(names) - shown
    return head + ", ".join(names[:shown]) + (f" and {more} more" if more else "") + tail


def questions_path(value: str | Path | None, default: Path) -> Path:
    """``--questions``: the study's questions file, the shipped ``default`` when the option is not given;
    a file that is not there is refused (a UsageError naming the option) before anything is read."""
    if value is None:
        return default
    if not Path(value).is_file():
        raise UsageError(f"--questions {value}: no such file")
    return Path(value)


def write_csv(table: pd.DataFrame, path: Path) -> Path:
    """``table`` as CSV (no index) at ``path``, whole or not at all; returns the path."""
    return write_atomic(path, lambda tmp: table.to_csv(tmp, index=False))


@dataclass
class Report:
    """A study's answer as the files it writes, in order: each ``(name, part)`` is text (written as UTF-8),
    a table (``.csv``, or ``.parquet`` by the name) or a figure (a function that draws into the path it is
    given, its format read from the name).  Every study's report is written by ``write``, through the
    store's atomic writers: a stopped or failed report leaves the old file or the new one, never half of one.
    """

    parts: list[tuple[str, str | pd.DataFrame | Callable[[Path], object]]]

    @classmethod
    def of(cls, stem: str, markdown: str, *, table: pd.DataFrame | None = None,
           figure: Callable[[Path], object] | None = None, extra: Iterable[tuple[str, str]] = ()) -> Report:
        """The usual shape: ``stem.md``, then ``stem.csv`` of ``table``, each ``(name, text)`` of ``extra``
        and ``stem.png`` drawn by ``figure(path)``, those given."""
        parts: list[tuple[str, str | pd.DataFrame | Callable[[Path], object]]] = [(f"{stem}.md", markdown)]
        parts += [(f"{stem}.csv", table)] if table is not None else []
        parts += list(extra)
        parts += [(f"{stem}.png", figure)] if figure is not None else []
        return cls(parts)

    def text(self, name: str) -> str:
        """The text part called ``name`` (a command prints its report's markdown as it writes it).

        Raises:
            ArgumentError: the report has no text part of that name.
        """
        for part_name, part in self.parts:
            if part_name == name and isinstance(part, str):
                return part
        raise ArgumentError(f"the report has no text part {name!r}")

    def write(self, out: str | Path) -> list[Path]:
        """Write every part into ``out`` (created when missing); returns the files, in the parts' order."""
        folder = writable_dir(Path(out))
        files = []
        for name, part in self.parts:
            path = folder / name
            if isinstance(part, str):
                files.append(write_text_atomic(part, path, "utf-8"))
            elif isinstance(part, pd.DataFrame):
                files.append(write_parquet_atomic(part, path) if path.suffix == ".parquet" else write_csv(part, path))
            else:
                files.append(write_atomic(path, part, keep_suffix=True))
        return files


class Study(ABC):
    """A declared study, the shape every study's command takes: its declaration file, and ``answer``, its
    answers from the stores it reads as a ``Report`` (the files it writes, in order), written by ``write``
    through ``Report.write`` (the store's atomic writers).  A study keeps only what is its own: its
    settings, the rule of each question, its tables and figure.
    """

    #: the study's declaration file, read once (None: a study that reads its questions elsewhere)
    declaration: Declaration | None = None

    @abstractmethod
    def answer(self, store) -> Report:
        """The study's answers from ``store`` (a store, or the stores or folder of stores it is answered
        from) as the files it writes; nothing is written here.

        Raises:
            UsageError: the store holds nothing the study can answer from.
        """

    def write(self, store, out: str | Path) -> list[Path]:
        """``answer(store)`` written into ``out`` (created when missing); returns the files, in order."""
        return self.answer(store).write(out)


def drawn(make: Callable[[], object], **options) -> Callable[[Path], None]:
    """A figure part of a ``Report``: ``make()`` builds the matplotlib figure when the report is written,
    ``savefig(path, **options)`` saves it and it is closed (pyplot keeps every open figure alive)."""
    def draw(path: Path) -> None:
        import matplotlib.pyplot as plt  # only when a figure is drawn: matplotlib is slow to import

        fig = make()
        try:
            fig.savefig(path, **options)  # type: ignore[attr-defined]
        finally:
            plt.close(fig)  # type: ignore[arg-type]
    return draw


def write(out: Path, stem: str, markdown: str, *, table: pd.DataFrame | None = None,
          figure: Callable[[Path], object] | None = None, extra: Iterable[tuple[str, str]] = ()) -> list[Path]:
    """``Report.of(...).write(out)``: ``stem.md`` (and ``stem.csv`` of ``table``, each ``(name, text)`` of
    ``extra``, ``stem.png`` by ``figure(path)``) in ``out``, written once the study's answers exist."""
    return Report.of(stem, markdown, table=table, figure=figure, extra=extra).write(out)
