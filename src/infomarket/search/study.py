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
from dataclasses import dataclass, field
from pathlib import Path

from ..config.load import validate
from ..config.schema import Experiment
from ..analysis.study import Check, Declaration, questions_path
from ..analysis.study import settings as study_settings
from ..errors import ConfigError, UsageError
from ..registry import payments
from ..runner.plan import conditions
from .baselines import rotation_grid
from .objective import OBJECTIVES
from .space import NAMES

QUESTIONS = Path(__file__).with_name("questions.toml")
#: the declared settings, baselines and questions, with their record of amendments (printed in the report)
DECLARATION = Declaration.read(QUESTIONS, "search/questions.toml")
ATTACKER = "attacker"


@dataclass(frozen=True)
class Settings:
    """The declared search settings (``questions.toml`` ``[search]``); every key has a default here."""

    budget: int = 256              # evaluations per cell for the global search; the random search gets as many
    popsize: int = 8               # CMA-ES population of the first restart (IPOP doubles it per restart)
    sigma0: float = 0.3            # CMA-ES step size, in the unit cube
    restarts: int = 4              # CMA-ES restarts, each from its own start point
    spread: float = 0.25           # share of the budget spent on start points spread over the cube (Sobol)
    runs: int = 8                  # runs per evaluation; the candidates of one generation share seeds
    finalists: int = 8             # best distinct points per searcher entering the race
    race: tuple[int, ...] = (8, 16, 32)  # cumulative runs per raced attack at each stage (selection seeds)
    keep: float = 0.5              # fraction of a race's attacks kept after each stage (at least 2)
    confirmation_runs: int = 64    # runs per chosen attack on the confirmation seeds
    grid_step: float = 15.0        # degrees between the rotation grid's baselines (search.baselines)
    objective: str = "items"
    seed: int = 23023
    pool_baselines: bool = False   # the baselines race in the search's own pool (the search keeps the best)
    gate_rounds: int = 0           # rounds of opening one gate at a time on the best point (search.structured)
    local: int = 0                 # the first restarts are local: from the best points found, step local_sigma
    local_sigma: float = 0.05      # CMA-ES step size of a local restart, in the unit cube
    leaders: int = 0               # the best start-phase points run again on leader_runs seeds before each choice
    leader_runs: int = 16          # (cumulative) runs of a re-evaluated leader, on the start phase's seeds
    validation: int = 0            # seeds per planted weakness searched before the study (search.validate)
    confirm_top: int = 1           # the race's best attacks of each group confirmed (role, role_2 .. role_k)
    refine: int = 0                # widest rounds of the last phase's moves kept in the budget (search.refine)
    refine_step: float = 0.08      # its first step, in the unit cube (halved after a round that finds nothing)

    @property
    def generations(self) -> int:
        """Batches of the random search (``popsize`` points each, ``budget`` in all)."""
        return -(-self.budget // self.popsize)


def _whole(v) -> bool:
    """A whole number, not a flag (``True`` is an int to Python, never a count to a study)."""
    return isinstance(v, int) and not isinstance(v, bool)


def _race(s: Settings) -> bool:
    """Cumulative runs per stage: whole numbers from 2 up, each above the one before."""
    r = s.race
    return (isinstance(r, tuple) and bool(r) and all(_whole(x) for x in r) and r[0] >= 2
            and all(b > a for a, b in zip(r, r[1:])))


#: the rules of every setting (``analysis.study.settings``), as the parser of every study takes them
WHOLE = {"budget": 1, "popsize": 2, "restarts": 1, "runs": 1, "finalists": 1, "confirmation_runs": 2, "seed": 0,
         "gate_rounds": 0, "local": 0, "leaders": 0, "leader_runs": 1, "validation": 0, "confirm_top": 1, "refine": 0}
NUMBERS = (("sigma0", 0.0, 1.0), ("keep", 0.0, 1.0), ("grid_step", 0.0, 180.0), ("local_sigma", 0.0, 1.0),
           ("refine_step", 0.0, 0.5))
CHECKS: tuple[Check, ...] = (
    ("race", _race, "cumulative runs per stage, whole numbers from 2 up, each above the one before (e.g. [8, 16, 32])"),
    ("spread", lambda s: not isinstance(s.spread, bool) and isinstance(s.spread, (int, float))
     and 0.0 <= s.spread < 1.0, "a share of the budget in [0, 1) is expected"),
    ("local", lambda s: not (_whole(s.local) and _whole(s.restarts)) or s.local <= s.restarts,
     "at most as many local restarts as restarts is expected"),
    ("objective", lambda s: s.objective in OBJECTIVES, f"one of {', '.join(OBJECTIVES)} is expected"))


def settings(table: dict, overrides: dict | None = None,
             source: str = "search settings (questions.toml [search] or an option)") -> Settings:
    """The ``Settings`` of a ``[search]`` table with ``overrides`` (None values ignored) over it, read by the
    studies' one parser (``analysis.study.settings``): an unknown key or a value out of range is a
    UsageError naming it.  A budget below one population makes one smaller generation."""
    given = {**table, **{k: v for k, v in (overrides or {}).items() if v is not None}}
    if _whole(given.get("budget")) and given["budget"] < given.get("popsize", Settings.popsize):
        given["popsize"] = max(2, given["budget"])  # a budget below one population: one smaller generation
    if isinstance(given.get("race"), list):
        given["race"] = tuple(given["race"])
    return study_settings(Settings, given, None, source, whole=WHOLE, flags=("pool_baselines",), numbers=NUMBERS,
                          checks=CHECKS)


@dataclass(frozen=True)
class Learner:
    """The adaptive attacker's training (``questions.toml`` ``[adaptive]``; budget 0: not run)."""

    budget: int = 0        # evaluations per cell
    pairs: int = 8         # antithetic pairs per generation
    runs: int = 4          # runs per evaluation
    sigma: float = 0.05    # the perturbations' step
    lr: float = 0.02       # the learning rate


def _finite(v) -> bool:
    """A finite number above 0, not a flag: a step or a rate the training can take."""
    return not isinstance(v, bool) and isinstance(v, (int, float)) and 0 < v < float("inf")


def learner(table: dict, overrides: dict | None = None, source: str = "questions.toml") -> Learner:
    """The ``Learner`` of an ``[adaptive]`` table with ``overrides`` (None ignored) over it, read by the
    studies' one parser: a bad key or value is a UsageError naming it."""
    return study_settings(Learner, table, overrides, f"{source} [adaptive] or an option",
                          whole={"budget": 0, "pairs": 1, "runs": 1},
                          checks=[("sigma", lambda s: _finite(s.sigma), "a finite number above 0 is expected"),
                                  ("lr", lambda s: _finite(s.lr), "a finite number above 0 is expected")])


@dataclass(frozen=True)
class Cell:
    """One defence against one Byzantine count: the configuration the attackers' parameters go into."""

    defence: str
    byzantines: int
    config: Experiment  # validated, no sweep; group 1 runs `attacker`

    @property
    def experiment(self) -> str:
        """The cell's experiment name in the store: study, defence and Byzantine count (``NAME.DEFENCE.bK``)."""
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
    """A study: its experiment, settings, and baselines (the declared hand-written attacks, the truthful
    ``reference`` among them, then the rotation grid), each a point of the attacker's parameters."""

    experiment: Experiment
    settings: Settings
    baselines: dict[str, dict[str, float]]
    reference: str | None
    questions: dict = field(default_factory=dict)
    pending: dict = field(default_factory=dict)
    declaration_path: Path = QUESTIONS  # the questions file declaring it (its commit goes into the report)


def read(path: str | Path | None = None) -> Declaration:
    """The study's questions file: the shipped one (read once, with the package), or a file like it."""
    if path is None:
        return DECLARATION
    return Declaration.read(questions_path(path, QUESTIONS), Path(path).name)


def load_declarations(path: Path = QUESTIONS) -> dict:
    """The attack-search study's declarations (its questions file, or ``path``) as parsed TOML, each file
    read once (``read``)."""
    return read(None if Path(path) == QUESTIONS else path).data


def load(experiment: Experiment, declarations: dict | None = None, *, path: Path = QUESTIONS, **overrides) -> Study:
    """The study of ``experiment`` with the declared settings, ``overrides`` (None values ignored) applied;
    ``path``: the questions file the declarations were read from."""
    d = DECLARATION.data if declarations is None else declarations
    settings_ = settings(d.get("search", {}), overrides)
    baselines, reference = {}, None
    for name, b in d.get("baselines", {}).items():
        unknown = set(b.get("params", {})) - set(NAMES)
        if unknown:
            raise ConfigError(f"{QUESTIONS.name}: baseline {name}: unknown attacker parameters {sorted(unknown)}")
        baselines[name] = dict(b.get("params", {}))
        if b.get("reference"):
            reference = name
    for name, params in rotation_grid(settings_.grid_step).items():
        if name in baselines:
            raise ConfigError(f"{QUESTIONS.name}: baseline {name}: the name of a rotation-grid baseline "
                              f"(search.baselines); give the declared one another name")
        baselines[name] = params
    return Study(experiment, settings_, baselines, reference, d.get("questions", {}), d.get("pending_defences", {}),
                 Path(path))


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
