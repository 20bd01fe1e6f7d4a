"""The study a defence search runs: its experiment, declared settings, families, and inner attack search.

Everything comes from ``questions.toml`` beside this module (declared before the study's runs), with
command-line overrides; the experiment gives the base configuration, the Byzantine counts and the existing
defences.  Every value is checked here, before any run, so a mistake is one message and nothing written.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..analysis.study import Declaration, questions_path
from ..analysis.study import settings as study_settings
from ..config.load import validate
from ..config.schema import Experiment
from ..errors import ConfigError, UsageError
from ..runner.plan import conditions
from ..search import study as attack_study
from ..search.restarts import stream
from .families import EXISTING, Candidate, Family, configure, existing, parse_family

QUESTIONS = Path(__file__).with_name("questions.toml")
DECLARATION = Declaration.read(QUESTIONS, "defence/questions.toml")


@dataclass(frozen=True)
class Settings:
    """The outer search's declared settings (``[defence]``)."""

    candidates: int = 8
    refine: int = 4
    refine_sigma: float = 0.15
    cost_runs: int = 16
    target: int = 3
    max_cost: float = 0.05
    frontier: int = 6
    confirmation_runs: int = 128
    seed: int = 71041
    #: judge every candidate at every Byzantine count in the outer search; when false, at the target count
    #: only (the trade and the frontier read no other), and the confirmed candidates at the others before
    #: their confirmation, on the same seeds: the same numbers for them, a third of the inner runs for the rest
    every_count: bool = True


WHOLE = {"candidates": 1, "refine": 0, "cost_runs": 2, "target": 0, "frontier": 0, "confirmation_runs": 2, "seed": 0}


def settings(table: dict, overrides: dict | None = None,
             source: str = "defence/questions.toml [defence] or an option") -> Settings:
    """``Settings`` from ``table`` with ``overrides`` (None ignored); a bad key or value is a UsageError
    (the studies' one parser, ``analysis.study.settings``)."""
    return study_settings(Settings, table, overrides, source, whole=WHOLE, flags=("every_count",),
                          numbers=(("refine_sigma", 0.0, 1.0), ("max_cost", 0.0, 1.0)))


@dataclass(frozen=True)
class Study:
    """A defence search: the experiment, outer settings, the inner attack search, the families chosen."""

    experiment: Experiment
    settings: Settings
    inner: attack_study.Study
    families: dict[str, Family]
    existing: dict[str, dict]             # the experiment's own defences: name -> key paths
    undefended: dict
    byzantines: tuple[int, ...]
    questions: dict = field(default_factory=dict)
    declaration: Declaration = DECLARATION    # the questions file: its path, tables and record

    @property
    def robots(self) -> int:
        """The swarm's size, kept whatever the defence or the Byzantine count."""
        return self.experiment.swarm.robots

    def base(self) -> dict:
        """The experiment as a plain dict, the base each candidate's configuration is built from."""
        return self.experiment.model_dump()

    def config(self, candidate: Candidate, byzantines: int) -> Experiment:
        """The experiment with ``candidate``'s defence settings and ``byzantines`` attackers.

        Raises:
            ConfigError: the combination is not a valid experiment (the message names the candidate).
        """
        where = f"{self.experiment.name}: defence {candidate.label} with {byzantines} Byzantine(s)"
        return configure(self.base(), byzantines, self.robots, candidate.settings(self.families), where)

    def undefended_config(self) -> Experiment:
        """The swarm without Byzantines nor defences: a defence's cost is its loss of items against this swarm."""
        where = f"{self.experiment.name}: the undefended swarm"
        return configure(self.base(), 0, self.robots, self.undefended, where)

    def existing_candidates(self) -> list[Candidate]:
        """The experiment's own defences as candidates, searched beside the families' points."""
        return [Candidate(name, EXISTING, set=dict(s), origin="existing") for name, s in self.existing.items()]


def read(path: str | Path | None) -> Declaration:
    """The study's questions file: the shipped one, or a file like it (a user's own families and rules)."""
    if path is None:
        return DECLARATION
    return Declaration.read(questions_path(path, QUESTIONS))


def load(experiment: Experiment, declaration: Declaration | None = None, *, families: list[str] | None = None,
         byzantines: list[int] | None = None, inner: dict | None = None, **overrides) -> Study:
    """The declared study of ``experiment``, restricted to ``families`` and ``byzantines`` when given
    (``existing`` names the experiment's own defences), with ``overrides`` of the outer settings and
    ``inner`` of the inner search's."""
    declaration = declaration or DECLARATION
    d = declaration.data
    s = settings(d.get("defence", {}), overrides)
    table = {**d.get("inner", {}), **{k: v for k, v in (inner or {}).items() if v is not None}}
    table["seed"] = stream(s.seed, "inner") % (2 ** 31)  # the inner searches' seed sets, keyed by the study's
    inner_study = attack_study.load(experiment, {**attack_study.DECLARATION.data, "search": table})
    unknown = sorted(set(d) - {"defence", "inner", "families", "undefended", "questions", "amendments", "deviations"})
    if unknown:
        raise ConfigError(f"{declaration.path}: unknown table [{unknown[0]}]; allowed: defence, inner, families, "
                          f"undefended, questions, amendments, deviations")
    declared = {n: parse_family(n, t, declaration.path.name) for n, t in (d.get("families") or {}).items()}
    have = [*declared, EXISTING]
    for f in families or []:
        if f not in have:
            raise UsageError(f"--family {f}: not a family of the study; allowed: {', '.join(have)}")
    chosen = {n: f for n, f in declared.items() if not families or n in families}
    exist = existing(experiment) if not families or EXISTING in families else {}
    _distinct_labels(declared, existing(experiment), s, declaration.path.name)
    counts = list(dict.fromkeys(int(c.keys["byzantines"]) for c in conditions(experiment)))
    for b in byzantines or []:
        if b not in counts:
            raise UsageError(f"--byzantines {b}: not a count of {experiment.name}; allowed: "
                             f"{', '.join(map(str, counts))}")
    if s.target not in counts:
        raise UsageError(f"target = {s.target}: not a Byzantine count of {experiment.name}; allowed: "
                         f"{', '.join(map(str, counts))}")
    use = tuple(b for b in counts if not byzantines or b in byzantines or b == s.target)
    undefended = dict((d.get("undefended") or {}).get("set") or {})
    if not undefended:
        raise ConfigError(f"{declaration.path.name}: [undefended] set: the swarm the cost is measured against is "
                          f"missing")
    return Study(experiment, s, inner_study, chosen, exist, undefended, use, d.get("questions", {}), declaration)


def _distinct_labels(families: dict[str, Family], exist: dict, s: Settings, source: str) -> None:
    """Every candidate's label (``FAMILYk``, and the existing defences' names) names its runs in the store:
    two candidates with one label would share runs, so a collision is refused before anything runs."""
    for name in families:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise ConfigError(f"{source}: [families.{name}]: a family's name is letters, digits and _ "
                              f"(it names the store's experiments)")
        clash = sorted(n for n in exist if re.fullmatch(rf"{re.escape(name)}\d+", n)
                       and int(n[len(name):]) < s.candidates + s.refine)
        if clash:
            raise ConfigError(f"{source}: [families.{name}]: its candidates' labels ({name}0, {name}1, ...) "
                              f"include {clash[0]!r}, an existing defence of the experiment; rename the family")


def check(study: Study, candidates: list[Candidate]) -> None:
    """Every configuration the study will run, built and validated before any run."""
    study.undefended_config()
    for c in candidates:
        for b in (0, *study.byzantines):
            study.config(c, b)


def with_length(study: Study, steps: int | None, transitory: int | None) -> Study:
    """The study with its runs' length changed (a reduced study); the declared one otherwise."""
    if steps is None and transitory is None:
        return study
    data = study.experiment.model_dump()
    if steps is not None:
        data["steps"] = steps
    if transitory is not None:
        data["transitory"] = transitory
    exp = validate(data, f"{study.experiment.name} with --steps/--transitory")
    return replace(study, experiment=exp, inner=replace(study.inner, experiment=exp))


def floor(f: float, n: float) -> float:
    """Allouah et al.'s lower bound on any aggregator's robustness coefficient: kappa >= f / (n - 2f)
    (infinite once the liars are half the voices or more)."""
    return f / (n - 2 * f) if n - 2 * f > 0 else math.inf
