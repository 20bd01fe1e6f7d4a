"""Defence families: the parameter spaces a defence search explores, and the candidates it draws from them.

A family is a defence with free parameters: fixed settings (``set``: key paths of the experiment, as a
sweep axis writes them) and parameters, each a range over one or more key paths (a value the attackers
must know, like Θ, is written to their group too).  A candidate is one point of a family, or one of the
study experiment's existing defences (its ``defence`` axis), which have no free parameters.  Points are
drawn in the unit cube and mapped to each parameter's range (linear, logarithmic or whole numbers), so
one scrambled Sobol design and one perturbation rule serve every family.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from ..config.load import validate
from ..config.schema import Experiment
from ..errors import ConfigError
from ..runner.keypaths import set_path
from ..search.restarts import design, stream

KINDS = ("float", "int", "log")
#: the family of the study experiment's existing defences (no free parameters)
EXISTING = "existing"


@dataclass(frozen=True)
class Param:
    """One free parameter: its name, the key paths it writes, its range and scale, its default."""

    name: str
    paths: tuple[str, ...]
    low: float
    high: float
    kind: str = "float"
    default: float | None = None

    def value(self, u: float) -> float:
        """The parameter's value at ``u`` in [0, 1]: linear, logarithmic, or a whole number (each of the
        ``high - low + 1`` numbers takes an equal share of [0, 1])."""
        u = min(max(float(u), 0.0), 1.0)
        if self.kind == "int":
            return float(min(int(self.low + math.floor(u * (self.high - self.low + 1))), int(self.high)))
        if self.kind == "log":
            return float(math.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low))))
        return float(self.low + u * (self.high - self.low))

    def unit(self, v: float) -> float:
        """The inverse of ``value`` (a whole number maps to the middle of its share)."""
        if self.kind == "int":
            return (v - self.low + 0.5) / (self.high - self.low + 1)
        if self.kind == "log":
            return (math.log(v) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (v - self.low) / (self.high - self.low) if self.high > self.low else 0.5


@dataclass(frozen=True)
class Family:
    """A defence with free parameters (``params``) over fixed settings (``set``)."""

    name: str
    description: str
    set: dict
    params: tuple[Param, ...] = ()

    def point(self, u) -> dict[str, float]:
        """Parameter name -> value at the unit-cube point ``u``."""
        return {p.name: p.value(x) for p, x in zip(self.params, u)}


@dataclass(frozen=True)
class Candidate:
    """One defence to judge: a family's point (``values``) or an existing defence (``set`` only)."""

    label: str
    family: str
    values: dict[str, float] = field(default_factory=dict)
    set: dict = field(default_factory=dict)
    origin: str = "design"  # default, design, refine, existing

    def settings(self, families: dict[str, Family]) -> dict[str, object]:
        """Every key path this candidate writes, in order: the family's fixed settings, then its values."""
        out = dict(self.set)
        fam = families.get(self.family)
        if fam is not None:
            out.update(copy.deepcopy(fam.set))
            for p in fam.params:
                v = self.values[p.name]
                for path in p.paths:
                    out[path] = int(v) if p.kind == "int" else v
        return out


def _number(v, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(f"{where}: {v!r}: a finite number is expected")
    return float(v)


def parse_family(name: str, table: dict, source: str) -> Family:
    """A ``[families.NAME]`` table: ``description``, ``set`` and ``params.P = {paths, low, high, kind,
    default}``; every mistake is a ConfigError naming the key."""
    where = f"{source} [families.{name}]"
    allowed = {"description", "set", "params"}
    for k in table:
        if k not in allowed:
            raise ConfigError(f"{where}: unknown key {k!r}; allowed: {', '.join(sorted(allowed))}")
    if name == EXISTING:
        raise ConfigError(f"{where}: {EXISTING!r} names the study experiment's own defences; choose another name")
    params = []
    for pname, p in (table.get("params") or {}).items():
        pw = f"{where} params.{pname}"
        unknown = set(p) - {"paths", "low", "high", "kind", "default"}
        if unknown:
            raise ConfigError(f"{pw}: unknown key {sorted(unknown)[0]!r}; allowed: paths, low, high, kind, default")
        paths = p.get("paths")
        if isinstance(paths, str):
            paths = [paths]
        if not paths or not all(isinstance(x, str) and x for x in paths):
            raise ConfigError(f"{pw}: paths: one or more key paths like \"payment.params.theta\" are expected")
        kind = p.get("kind", "float")
        if kind not in KINDS:
            raise ConfigError(f"{pw}: kind = {kind!r}; allowed: {', '.join(KINDS)}")
        low, high = _number(p.get("low"), f"{pw} low"), _number(p.get("high"), f"{pw} high")
        if not low < high or (kind == "log" and low <= 0) or (kind == "int" and (low != int(low) or high != int(high))):
            raise ConfigError(f"{pw}: low = {low:g}, high = {high:g}: low must be below high"
                              + (", both above 0" if kind == "log" else "")
                              + (", both whole numbers" if kind == "int" else ""))
        default = p.get("default")
        if default is not None:
            default = _number(default, f"{pw} default")
            if not low <= default <= high:
                raise ConfigError(f"{pw}: default = {default:g} is outside [{low:g}, {high:g}]")
        params.append(Param(pname, tuple(paths), low, high, kind, default))
    return Family(name, str(table.get("description", "")), dict(table.get("set") or {}), tuple(params))


def existing(experiment: Experiment) -> dict[str, dict]:
    """The study experiment's defences (its ``defence`` axis): name -> the key paths each sets."""
    sw = experiment.sweep
    axis = sw.axes.get("defence") if sw is not None else None
    if not axis:
        raise ConfigError(f"{experiment.name}: a defence search needs an experiment with a `defence` sweep axis "
                          f"(like the shipped attack_search)")
    return {str(a.value): dict(a.set) for a in axis}


def candidates(family: Family, n: int, seed: int) -> list[Candidate]:
    """The family's first candidates: its default point, then ``n - 1`` points of a scrambled Sobol design
    over its unit cube (a family without parameters: the default alone)."""
    start = {p.name: p.default if p.default is not None else p.value(0.5) for p in family.params}
    out = [Candidate(f"{family.name}0", family.name, start, origin="default")]
    if family.params and n > 1:
        for k, u in enumerate(design(n - 1, len(family.params), stream(seed, "design", family.name)), start=1):
            out.append(Candidate(f"{family.name}{k}", family.name, family.point(u)))
    return out


def refine(family: Family, best: Candidate, n: int, start: int, seed: int, sigma: float) -> list[Candidate]:
    """``n`` points around ``best`` in the unit cube (normal steps of ``sigma``, clipped), labelled from
    ``start`` on: the second round of the outer search, where the first round found the best trade."""
    if not family.params or n <= 0:
        return []
    rng = np.random.default_rng(stream(seed, "refine", family.name, best.label))
    centre = np.array([p.unit(best.values[p.name]) for p in family.params])
    pts = np.clip(centre + sigma * rng.standard_normal((n, len(family.params))), 0.0, 1.0)
    return [Candidate(f"{family.name}{start + k}", family.name, family.point(u), origin="refine")
            for k, u in enumerate(pts)]


def configure(base: dict, byzantines: int, robots: int, settings: dict[str, object], where: str) -> Experiment:
    """The study experiment's base configuration (``base``: no sweep) with ``byzantines`` attackers in group
    1 and the candidate's key paths written; validated (an impossible setting is a ConfigError naming it)."""
    data = copy.deepcopy(base)
    data["sweep"] = None
    set_path(data, "swarm.groups[0].count", robots - byzantines, where)
    set_path(data, "swarm.groups[1].count", byzantines, where)
    for path, value in settings.items():
        set_path(data, path, copy.deepcopy(value), where)
    return validate(data, where)
