"""The study an attack search runs: its cells (defence x Byzantine count), search settings and the
hand-written attacks it is compared with.

The cells are the ``defence`` and ``byzantines`` sweep axes of an experiment (the shipped
``attack_search``, or any file with group 0 honest and group 1 of behaviour ``attacker``); defences in
``questions.toml``'s ``[pending_defences]`` join the axis once the payment scheme they need is registered.
Settings and baselines come from ``questions.toml`` (declared before the study's runs), command-line
options override the settings.
"""
from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..config.load import validate
from ..config.schema import Experiment
from ..analysis.study import Declaration
from ..errors import ConfigError, UsageError
from ..registry import payments
from ..runner.plan import conditions
from .objective import OBJECTIVES
from .space import NAMES

QUESTIONS = Path(__file__).with_name("questions.toml")
#: the declared settings, baselines and questions, with their record of amendments (printed in the report)
DECLARATION = Declaration.read(QUESTIONS, "search/questions.toml")
ATTACKER = "attacker"


@dataclass(frozen=True)
class Settings:
    budget: int = 128
    popsize: int = 8
    sigma0: float = 0.3
    runs: int = 8
    heldout_runs: int = 32
    best: int = 3
    objective: str = "items"
    seed: int = 23023

    @property
    def generations(self) -> int:
        return max(1, self.budget // self.popsize)


@dataclass(frozen=True)
class Cell:
    """One defence against one Byzantine count: the configuration the attackers' parameters go into."""

    defence: str
    byzantines: int
    config: Experiment  # validated, no sweep; group 1 runs `attacker`

    @property
    def experiment(self) -> str:
        return f"{self.config.name}.{self.defence}.b{self.byzantines}"

    def with_attack(self, params: dict[str, float], *, steps: int | None = None,
                    transitory: int | None = None) -> Experiment:
        """The cell's configuration with the attackers' parameters ``params`` (the known contract kept)."""
        data = self.config.model_dump()
        data["name"] = self.experiment
        g = data["swarm"]["groups"][1]
        g["params"] = {**g["params"], **params}
        if steps is not None:
            data["steps"] = steps
        if transitory is not None:
            data["transitory"] = transitory
        return validate(data, f"{self.experiment} with attack {params}")


@dataclass(frozen=True)
class Study:
    experiment: Experiment
    settings: Settings
    baselines: dict[str, dict[str, float]]
    reference: str | None
    questions: dict = field(default_factory=dict)
    pending: dict = field(default_factory=dict)


def load_declarations(path: Path = QUESTIONS) -> dict:
    return tomllib.loads(Path(path).read_text())


def load(experiment: Experiment, declarations: dict | None = None, **overrides) -> Study:
    """The study of ``experiment`` with the declared settings, ``overrides`` (None values ignored) applied."""
    d = load_declarations() if declarations is None else declarations
    known = Settings.__dataclass_fields__
    base = {k: v for k, v in d.get("search", {}).items() if k in known}
    base.update({k: v for k, v in overrides.items() if v is not None})
    if "budget" in base and base["budget"] < base.get("popsize", Settings.popsize):
        base["popsize"] = max(2, base["budget"])  # a budget below one population: one smaller generation
    settings = Settings(**base)
    if settings.objective not in OBJECTIVES:
        raise UsageError(f"--objective {settings.objective}: unknown; allowed: {', '.join(OBJECTIVES)}")
    if settings.best < 1 or settings.popsize < 2 or settings.runs < 1 or settings.heldout_runs < 2:
        raise UsageError("attack-search needs --best >= 1, a population of at least 2, --runs >= 1 and "
                         "--heldout-runs >= 2")
    baselines, reference = {}, None
    for name, b in d.get("baselines", {}).items():
        unknown = set(b.get("params", {})) - set(NAMES)
        if unknown:
            raise ConfigError(f"{QUESTIONS.name}: baseline {name}: unknown attacker parameters {sorted(unknown)}")
        baselines[name] = dict(b.get("params", {}))
        if b.get("reference"):
            reference = name
    return Study(experiment, settings, baselines, reference, d.get("questions", {}), d.get("pending_defences", {}))


def _with_pending(exp: Experiment, pending: dict) -> Experiment:
    """``exp`` with each pending defence whose scheme is registered added to its ``defence`` axis."""
    data = exp.model_dump()
    axis = data["sweep"]["axes"]["defence"]
    have = {a["value"] for a in axis}
    for name, p in pending.items():
        if name not in have and p.get("requires") in payments():
            axis.append({"value": name, "set": copy.deepcopy(p["set"])})
    return validate(data, exp.name)


def cells(study: Study, defences: list[str] | None = None, byzantines: list[int] | None = None) -> list[Cell]:
    """The study's cells, all or those named; an unknown name is a UsageError listing the allowed ones."""
    exp = study.experiment
    sw = exp.sweep
    if sw is None or set(sw.axes) != {"defence", "byzantines"} or sw.grid or sw.sample is not None:
        raise UsageError(f"{exp.name}: an attack search needs an experiment whose sweep has exactly the axes "
                         f"`defence` and `byzantines` (like the shipped attack_search)")
    groups = exp.swarm.groups
    if len(groups) != 2 or groups[1].behaviour != ATTACKER:
        raise UsageError(f"{exp.name}: an attack search needs two groups, the honest swarm first and the "
                         f"`{ATTACKER}` robots second")
    exp = _with_pending(exp, study.pending)
    conds = conditions(exp)
    have_d = list(dict.fromkeys(c.keys["defence"] for c in conds))
    have_b = list(dict.fromkeys(int(c.keys["byzantines"]) for c in conds))
    for want, have, what in ((defences, have_d, "--defence"), (byzantines, have_b, "--byzantines")):
        for w in want or []:
            if w not in have:
                waiting = [f"{n} (needs the scheme {p['requires']!r})" for n, p in study.pending.items()
                           if n == w]
                raise UsageError(f"{what} {w}: not a cell of {exp.name}"
                                 + (f": {waiting[0]}, not registered" if waiting else "")
                                 + f"; allowed: {', '.join(map(str, have))}")
    out = []
    for c in conds:
        d, b = c.keys["defence"], int(c.keys["byzantines"])
        if (defences and d not in defences) or (byzantines and b not in byzantines):
            continue
        if c.config.swarm.groups[1].behaviour != ATTACKER:
            raise UsageError(f"{exp.name} [{c.id}]: group 1 must stay `{ATTACKER}` in every cell")
        out.append(Cell(d, b, c.config.model_copy(update={"name": exp.name})))
    return out
