"""Experiment configuration: a validated, frozen description of one simulated setup.

Validation happens here, before anything runs: unknown keys, wrong types and impossible values are
all reported with the key's path (``swarm.groups[0].count``) and what is allowed (``config.load`` turns
them into one ``errors.ConfigError``), and so is a configuration whose memory need exceeds the limit
(``config.sizes``).  Defaults are the values of docs/model.md §1 that produced the paper's figures; ``swarm``
has none and is required.
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (BaseModel, StrictBool, ConfigDict, Field, ValidationError, ValidationInfo, field_validator,
                      model_validator)

from .. import plugins
from ..errors import ConfigError
from ..registry import behaviours, payments
from . import chain as chain_rules, messages, sizes, terrain
from .sample import Sample

#: Seeds are 63-bit everywhere (files, the command line, the Python API, the store's int64 columns).
from ..seeds import MAX_SEED  # one definition, infomarket.seeds

#: An experiment's name is also a folder name (``results/NAME``) and a label in tables: ASCII letters, digits
#: and ``_ - . + = ,``, starting with a letter, digit or ``_``, at most NAME_MAX characters (no path separators,
#: no control characters, never ``.`` or ``..``).
NAME_MAX = 100
NAME_PATTERN = r"^[A-Za-z0-9_][A-Za-z0-9_.+=,-]*$"

#: Bounds where the model needs them: a number that passes validation must run without overflowing or
#: dividing by zero.  Lengths (the arena, radii, speed, ranges, coordinates, noise) are at most MAX_LENGTH
#: (a million arenas of the paper's 1200: a step of 1e300 overflows the geometry); amounts of money at most
#: MAX_MONEY (so the swarm's total wealth, summed over a run's every reward, stays a finite float64); counts
#: of steps at most MAX_STEPS (so a clock plus any of them stays an int64); rule parameters at most
#: MAX_PARAM in size.
MAX_LENGTH = 1e9
MAX_MONEY = 1e12
MAX_STEPS = 10**12
MAX_PARAM = 1e12
PosFloat = Annotated[float, Field(gt=0, le=MAX_LENGTH, allow_inf_nan=False)]
NonNegFloat = Annotated[float, Field(ge=0, le=MAX_LENGTH, allow_inf_nan=False)]
Finite = Annotated[float, Field(ge=-MAX_LENGTH, le=MAX_LENGTH, allow_inf_nan=False)]
Money = Annotated[float, Field(ge=0, le=MAX_MONEY, allow_inf_nan=False)]
Param = Annotated[float, Field(ge=-MAX_PARAM, le=MAX_PARAM, allow_inf_nan=False)]
NonNegInt = Annotated[int, Field(ge=0, le=MAX_STEPS, strict=True)]
PosInt = Annotated[int, Field(gt=0, le=MAX_STEPS, strict=True)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Arena(_Strict):
    """``[arena]``: the rectangle the robots live in, ``width`` by ``height`` (the paper's 1200 x 600)."""
    width: PosFloat = 1200.0
    height: PosFloat = 600.0


class Site(_Strict):
    """A food or nest site: a disc of centre (x, y) and ``radius``."""
    x: Finite
    y: Finite
    radius: PosFloat = 50.0


class Rect(_Strict):
    """Axis-aligned rectangle obstacle, corners (x0, y0) and (x1, y1) with x0 < x1, y0 < y1."""

    shape: Literal["rect"]
    x0: Finite
    y0: Finite
    x1: Finite
    y1: Finite

    @model_validator(mode="after")
    def _ordered(self) -> Rect:
        if not (self.x0 < self.x1 and self.y0 < self.y1):
            raise ConfigError(f"a rect needs x0 < x1 and y0 < y1, got ({self.x0}, {self.y0}) - ({self.x1}, {self.y1})")
        return self


class CircleObstacle(_Strict):
    """Disc obstacle of centre (x, y)."""

    shape: Literal["circle"]
    x: Finite
    y: Finite
    radius: PosFloat


class Segment(_Strict):
    """Line segment obstacle (a thin wall) from (x0, y0) to (x1, y1); walls with gaps are several."""

    shape: Literal["segment"]
    x0: Finite
    y0: Finite
    x1: Finite
    y1: Finite

    @model_validator(mode="after")
    def _long(self) -> Segment:
        if self.x0 == self.x1 and self.y0 == self.y1:
            raise ConfigError(f"a segment needs two different end points, got ({self.x0}, {self.y0}) twice")
        return self


#: ``[[obstacles]]`` entries, told apart by ``shape`` (space.obstacles has the geometry).
Obstacle = Annotated[Rect | CircleObstacle | Segment, Field(discriminator="shape")]


class Robot(_Strict):
    """``[robot]``: every robot's body, motion, communication range and odometry error (docs/model.md lists each)."""
    radius: PosFloat = 8.0
    speed: PosFloat = 2.5
    communication_range: NonNegFloat = 50.0
    bias_mean: Finite = 0.05
    bias_sd: NonNegFloat = 0.05
    noise_sd: NonNegFloat = 0.05
    stop_time: NonNegInt = 0
    cooldown: NonNegInt = 0
    fuel_cost: Money = 0.0
    #: Two robots communicate only if no obstacle cuts the segment between them (space.obstacles).
    line_of_sight: StrictBool = False
    #: Robots are discs that cannot overlap: a move that would overlap another robot is not made.
    collisions: StrictBool = False
    #: The proximity sensors also fire for other robots' discs (as for obstacles; engine.terrain).
    sense_robots: StrictBool = False


class RandomWalk(_Strict):
    """``[random_walk]``: the exploration walk, turning angles wrapped Cauchy (``rho``), run lengths Lévy
    (``alpha``)."""
    #: below 1 - 1e-6: at 1 the turning angle's wrapped Cauchy density divides by zero
    rho: Annotated[float, Field(gt=0, le=0.999999)] = 0.9
    alpha: Annotated[float, Field(gt=0, le=2)] = 1.4


class Group(_Strict):
    """One group of the swarm: ``count`` robots of ``behaviour``, its parameters overridden by ``params``."""
    behaviour: str
    count: NonNegInt
    params: dict[str, Param] = Field(default_factory=dict)


class Swarm(_Strict):
    """``[swarm]``: ``robots`` robots made of ``groups``, whose counts must add up to it."""
    robots: PosInt = 25
    groups: list[Group] = Field(min_length=1)

    @model_validator(mode="after")
    def _counts(self) -> Swarm:
        for k, g in enumerate(self.groups):
            if g.count > self.robots:
                raise ConfigError(f"groups[{k}].count = {g.count} is more robots of {g.behaviour!r} than "
                                 f"the swarm has (robots = {self.robots})")
        total = sum(g.count for g in self.groups)
        if total != self.robots:
            raise ConfigError(f"the group counts add up to {total} but robots = {self.robots}; they must be equal")
        return self


class Payment(_Strict):
    """``[payment]``: the payment ``scheme`` and its ``params``, the robots' initial wealth, the reward and the
    stake."""
    scheme: str = "delayed"
    initial_wealth: Money = 1.0
    reward: Money = 1.0
    information_share: Annotated[float, Field(ge=0, le=1)] = 0.5
    stake: Money = 0.0
    #: Steps after which an open purchase's stake goes back to its seller (0 = never; docs/chain.md).
    stake_expiry: NonNegInt = 0
    #: Reputation that decays: each earlier settled sale of a seller counts this many times less at each
    #: later one in the reputation rules read (1 = never; docs/defences.md).
    reputation_decay: Annotated[float, Field(gt=0, le=1)] = 1.0
    params: dict[str, Param] = Field(default_factory=dict)


class Chain(_Strict):
    """Robots as blockchain nodes (docs/chain-model.md): ``consensus = "instant"`` (the default) is the
    paper's shared ledger, where every transaction applies at once; ``"poa"`` makes every robot a node
    with its own view of a Proof-of-Authority chain."""

    consensus: Literal["instant", "poa"] = "instant"
    #: Steps between a block and the next one its in-turn signer makes.
    period: PosInt = 1
    #: Robot ids allowed to make blocks (block h is in turn for signers[h % len]); empty: every robot.
    signers: list[NonNegInt] = Field(default_factory=list)
    #: Extra steps an out-of-turn signer waits after the period before it makes a block itself.
    out_of_turn_delay: PosInt = 1
    #: A backbone network also carries every transaction and block to every robot, ``latency`` steps late.
    backbone: StrictBool = False
    latency: NonNegInt = 0
    #: Probability that one message (a robot's head and pending transactions, to one neighbour, in one
    #: step) is lost.
    loss: Annotated[float, Field(ge=0, lt=1)] = 0.0
    #: Money per unit of gas; each reveal, deposit and settlement costs its measured gas (docs/gas.md).
    gas_price: Money = 0.0
    #: A block this many blocks below the canonical head is final (earlier, once every robot's head is
    #: on it); branches that do not contain it are dropped.
    finality: PosInt = 32
    #: [start, end): during steps start <= t < end no chain message (gossip, backbone) passes between the
    #: two sides of the perpendicular bisector of the first food site and the first nest; none by default.
    partition: tuple[NonNegInt, NonNegInt] | None = None

    @model_validator(mode="after")
    def _partition_window(self) -> Chain:
        if self.partition is not None and self.partition[1] <= self.partition[0]:
            raise ConfigError(f"chain.partition = [{self.partition[0]}, {self.partition[1]}]: the end step must "
                              f"come after the start step")
        return self

    @property
    def enabled(self) -> bool:
        """Whether the robots run their own chain (any consensus but ``instant``, the paper's ideal ledger)."""
        return self.consensus != "instant"


class AxisValue(_Strict):
    """One value of a named sweep axis: the label stored in results, and the keys it sets."""

    value: str | int | float
    set: dict[str, Any] = Field(min_length=1)


class Sweep(_Strict):
    """Conditions to run: the product of ``grid`` (dotted key -> values) and named ``axes``
    (name -> values, each setting several keys at once, e.g. the number of Byzantines)."""

    runs: PosInt | None = None
    grid: dict[str, list[Any]] = Field(default_factory=dict)
    axes: dict[str, list[AxisValue]] = Field(default_factory=dict)
    #: A sampled design (docs/sweeps.md, "Sampled designs"), instead of a grid and axes.
    sample: Sample | None = None

    @model_validator(mode="after")
    def _not_empty(self) -> Sweep:
        if self.sample is not None and (self.grid or self.axes):
            raise ConfigError("a sweep has either a grid and axes or a sample design, not both")
        if not self.grid and not self.axes and self.sample is None:
            raise ConfigError("a sweep needs a grid or axes with at least one key, or a [sweep.sample] design")
        for key, values in self.grid.items():
            if not values:
                raise ConfigError(f"grid.{key}: empty list of values")
        for name, values in self.axes.items():
            if not values:
                raise ConfigError(f"axes.{name}: empty list of values")
        return self


class Experiment(_Strict):
    """One setup: world, robots, swarm composition, payment scheme, run length, runs and seed."""

    name: str = "experiment"
    description: str = ""
    plugins: list[str] = Field(default_factory=list, description="modules to import that register rules")
    steps: PosInt = 15000
    transitory: NonNegInt = 0
    runs: PosInt = 1
    seed: Annotated[int, Field(ge=0, le=MAX_SEED, strict=True)] = 0
    history_every: NonNegInt = 0
    arena: Arena = Arena()
    food: Site | Annotated[list[Site], Field(min_length=1)] = Site(x=200.0, y=300.0)
    nest: Site | Annotated[list[Site], Field(min_length=1)] = Site(x=1000.0, y=300.0)
    obstacles: list[Obstacle] = Field(default_factory=list)
    robot: Robot = Robot()
    random_walk: RandomWalk = RandomWalk()
    swarm: Swarm
    payment: Payment = Payment()
    chain: Chain = Chain()
    sweep: Sweep | None = None

    @field_validator("name", mode="before")
    @classmethod
    def _safe_name(cls, name: Any) -> Any:
        if not isinstance(name, str):
            return name  # pydantic says "a valid string"
        if not name:
            raise ConfigError("an empty name; a name is used as a folder (results/NAME): give one")
        if len(name) > NAME_MAX:
            raise ConfigError(f"a name of {len(name)} characters; at most {NAME_MAX} (it is used as a folder)")
        if not re.fullmatch(NAME_PATTERN, name):
            raise ConfigError("a name may hold only ASCII letters, digits and _ - . + = , and must start with a "
                              "letter, digit or _ (it is used as a folder: no / or \\, no spaces or control "
                              "characters)")
        return name

    @field_validator("food", "nest", mode="before")
    @classmethod
    def _site_defaults(cls, value: Any, info: ValidationInfo) -> Any:
        """One site given in part (``[food]`` with only ``radius``) takes the default site's other keys."""
        if isinstance(value, dict):
            assert info.field_name is not None  # a field validator's
            default = cls.model_fields[info.field_name].default
            return {"x": default.x, "y": default.y, **value}
        return value

    @field_validator("plugins")
    @classmethod
    def _import_plugins(cls, entries: list[str], info: ValidationInfo) -> list[str]:
        base = (info.context or {}).get("base")
        resolved = [plugins.resolve(e, base) for e in entries]
        for e in resolved:
            try:
                plugins.load(e)
            except Exception as exc:  # noqa: BLE001 - a plugin's own error is the user's to see, in one line
                raise ConfigError(f"cannot load plugin {e!r}: {type(exc).__name__}: {exc}") from None
        return resolved

    @model_validator(mode="after")
    def _coherent(self) -> Experiment:
        if self.transitory >= self.steps:
            raise ConfigError(f"transitory = {self.transitory} must be smaller than steps = {self.steps}")
        w, h, r = self.arena.width, self.arena.height, self.robot.radius
        if w - 1 - 2 * r < 0 or h - 1 - 2 * r < 0:
            raise ConfigError(f"the arena ({w} x {h}) is too small for robots of radius {r}")
        for key in ("food", "nest"):
            for label, s in self._labelled_sites(key):
                if s.x - s.radius < 0 or s.x + s.radius > w or s.y - s.radius < 0 or s.y + s.radius > h:
                    raise ConfigError(f"{label} site at ({s.x}, {s.y}) with radius {s.radius} lies outside the "
                                     f"arena [0, {w}] x [0, {h}]")
        why = terrain.site_overlap(self)
        if why:
            raise ConfigError(why)
        if self.history_every > self.steps:
            raise ConfigError(f"history_every = {self.history_every} must be at most steps = {self.steps}")
        known = behaviours()
        for k, g in enumerate(self.swarm.groups):
            if g.behaviour not in known:
                raise ConfigError(f"swarm.groups[{k}].behaviour: unknown behaviour {g.behaviour!r}; "
                                 f"allowed: {', '.join(sorted(known))}")
            allowed = known[g.behaviour].params
            for p, v in g.params.items():
                if p not in allowed:
                    raise ConfigError(f"swarm.groups[{k}].params: {g.behaviour!r} has no parameter {p!r}; "
                                     f"allowed: {', '.join(allowed) or 'none'}")
                why = known[g.behaviour].check(p, v)
                if why:
                    raise ConfigError(f"swarm.groups[{k}].params.{p} = {v}: {why}")
            missing = [p for p in allowed if p not in g.params and p not in known[g.behaviour].defaults]
            if missing:
                raise ConfigError(f"swarm.groups[{k}].params: {g.behaviour!r} needs {', '.join(missing)}")
        schemes = payments()
        if self.payment.scheme not in schemes:
            raise ConfigError(f"payment.scheme: unknown scheme {self.payment.scheme!r}; "
                             f"allowed: {', '.join(sorted(schemes))}")
        if self.payment.stake > self.payment.initial_wealth:
            raise ConfigError(f"payment.stake = {self.payment.stake} is more than payment.initial_wealth = "
                              f"{self.payment.initial_wealth}: no seller could ever lock its stake, so every "
                              f"purchase would be refused; lower the stake or raise the initial wealth")
        spec = schemes[self.payment.scheme]
        for p, v in self.payment.params.items():
            if p not in spec.params:
                raise ConfigError(f"payment.params: scheme {spec.name!r} has no parameter {p!r}; "
                                 f"allowed: {', '.join(spec.params) or 'none'}")
            why = spec.check(p, v)
            if why:
                raise ConfigError(f"payment.params.{p} = {v}: {why}")
        missing = [p for p in spec.params if p not in self.payment.params and p not in spec.defaults]
        if missing:
            raise ConfigError(f"payment.params: scheme {spec.name!r} needs {', '.join(missing)}")
        chain_rules.check(self.chain, self.steps)  # contradictions refused; what cannot act, warned about
        if self.chain.enabled:
            for signer in self.chain.signers:
                if signer >= self.swarm.robots:
                    raise ConfigError(f"chain.signers: robot {signer} does not exist (robots = {self.swarm.robots})")
            if len(set(self.chain.signers)) != len(self.chain.signers):
                raise ConfigError("chain.signers: a robot is listed twice")
            if self.robot.fuel_cost > 0 or self.payment.stake_expiry > 0 or self.payment.reputation_decay < 1:
                raise ConfigError("chain.consensus = 'poa' does not model robot.fuel_cost, payment.stake_expiry or "
                                  "payment.reputation_decay yet; set them to 0 (decay 1) or use the instant ledger")
        too_big = sizes.run_too_big(self)
        if too_big:
            raise ConfigError(too_big)
        return self

    # ------------------------------------------------------------------ derived views
    def sites(self, key: str) -> list[Site]:
        """The sites of one kind (``food`` or ``nest``) as a list, whether the file gave one or several."""
        value = getattr(self, key)
        return list(value) if isinstance(value, list) else [value]

    def _labelled_sites(self, key: str) -> list[tuple[str, Site]]:
        value = getattr(self, key)
        if isinstance(value, list):
            return [(f"{key}[{k}]", s) for k, s in enumerate(value)]
        return [(key, value)]

    @property
    def terrain(self) -> bool:
        """Does this setup leave the paper's plane (obstacles, several sites of a kind, line of sight,
        collisions)?  Only then does the engine compile the terrain variant of the step (engine.step,
        engine.terrain)."""
        return bool(self.obstacles or self.robot.line_of_sight or self.robot.collisions or self.robot.sense_robots
                    or len(self.sites("food")) > 1 or len(self.sites("nest")) > 1)

    def behaviour_params(self, group: Group) -> dict[str, float]:
        """The parameters of ``group``'s behaviour in call order: the group's values, else the behaviour's
        defaults."""
        spec = behaviours()[group.behaviour]
        return {p: float(group.params.get(p, spec.defaults.get(p, 0.0))) for p in spec.params}

    def payment_params(self) -> dict[str, float]:
        """The payment scheme's parameters in call order: the experiment's values, else the scheme's defaults."""
        spec = payments()[self.payment.scheme]
        return {p: float(self.payment.params.get(p, spec.defaults.get(p, 0.0))) for p in spec.params}

    def with_overrides(self, **changes) -> Experiment:
        """A re-validated copy with top-level fields replaced (e.g. steps, runs, seed)."""
        data = self.model_dump()
        data.update(changes)
        return validate(data)  # one ConfigError naming the key; plugins are absolute paths or module names by now

    def config_hash(self) -> str:
        """Hash of everything that determines results (not name, description, runs or seed)."""
        data = self.model_dump(exclude={"name", "description", "runs", "seed", "sweep"})
        terrain.drop_defaults(data)  # setups on the paper's plane keep the hashes they always had
        if data["payment"].get("reputation_decay") == 1.0:
            data["payment"].pop("reputation_decay")  # and so do setups whose reputation does not decay
        if data.get("chain") == Chain().model_dump():
            data.pop("chain")  # and so do setups on the instant ledger
        elif data.get("chain", {}).get("partition", 0) is None:
            data["chain"].pop("partition")  # and chain setups without a partition
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


#: Union branches that pydantic names inside error locations (``food`` is one site or a list of sites;
#: an obstacle's ``shape`` picks its model): left out of the key paths users see.
_BRANCHES = {"Site": None, "list[Site]": None, "rect": Rect, "circle": CircleObstacle, "segment": Segment}


def validate(data: dict[str, Any], source: str = "configuration", base: Path | None = None) -> Experiment:
    """Validate a dictionary in our schema; raise ConfigError listing every problem.  ``base`` is the
    folder relative plugin paths are resolved against (the experiment file's)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: an experiment is a table of keys (a dict), got {type(data).__name__}")
    try:
        return Experiment.model_validate(data, context={"base": base})
    except RecursionError:
        raise ConfigError(f"{source}: nested too deeply to be an experiment") from None
    except ValidationError as exc:
        raise ConfigError(messages.invalid(source, exc, Experiment, _BRANCHES)) from None
