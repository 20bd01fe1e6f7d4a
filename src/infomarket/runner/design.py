"""Sampled designs: ``[sweep.sample]`` turned into conditions of a results store.

A design is a matrix drawn by SALib (Saltelli's Sobol' scheme, Morris trajectories or a Latin
hypercube), seeded from the experiment's master seed, so the same file gives the same design.  Row *i*
is the condition ``point=i`` of the store, with one column per sampled key: it is resumed, seeded
(``plan.condition_number``) and executed exactly like a grid point.  Integer keys (a group's count,
``swarm.robots``) are sampled on ``[low - 0.5, high + 0.5]`` and rounded, so every integer of the range
is equally likely; the analysis sees the raw value SALib drew.

Everything that can make a design unusable is refused before anything runs: unknown or non-numeric
keys, non-integer bounds of an integer key, two keys named alike, and any corner of the bounds at which
the experiment is invalid (every corner is validated like a file of its own).  The design's matrix and
settings are kept in the store (``STORE/designs/EXPERIMENT.parquet`` and ``.json``) so the analysis can
be redone from the store alone and a resumed sweep is checked against the design it started.  A Sobol'
design may grow in its store (``--samples`` doubled): its first points are the stored ones, so only the
new points run.
"""
from __future__ import annotations

import copy
import itertools
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..config.load import validate
from ..config.sample import BUILTIN_OUTPUTS, Sample
from ..config.schema import Experiment
from ..errors import ConfigError
from ..registry import behaviours
from ..store import StoreError
from ..store.files import write_atomic, write_text_atomic
from ..store.results import write_table
from .keypaths import KEY_PART, label, set_path

#: Corners checked exhaustively up to this many keys (2^D validations); beyond, the two extreme corners
#: and each key at each end with the others at the opposite end and at their low end.
MAX_FULL_CORNERS = 12
#: Outputs that need honest and Byzantine robots in every run.
NEEDS_BOTH = ("share_gap", "byzantine_share")


@dataclass(frozen=True)
class Design:
    """A design: its settings (``spec``) and the matrix ``X`` SALib drew (one row per point)."""

    experiment: str
    method: str
    samples: int
    second_order: bool
    levels: int
    seed: int
    keys: list[str]
    names: list[str]
    also: list[list[str]]
    low: list[float]
    high: list[float]
    integer: list[bool]
    remainder: str | None
    outputs: list[str]
    custom: dict[str, dict]
    salib: str
    X: np.ndarray = field(repr=False, compare=False)

    @property
    def points(self) -> int:
        """The number of points (rows of ``X``), each one condition of the sweep."""
        return len(self.X)

    def sampling_bounds(self) -> list[list[float]]:
        """The bounds SALib samples in: an integer key's range widened by half a step at each end, so each integer
        is drawn equally often once rounded."""
        return [[lo - 0.5, hi + 0.5] if integer else [lo, hi]
                for lo, hi, integer in zip(self.low, self.high, self.integer)]

    def problem(self) -> dict:
        """SALib's problem dictionary."""
        return {"num_vars": len(self.names), "names": list(self.names), "bounds": self.sampling_bounds()}

    def values(self) -> np.ndarray:
        """The values each point sets: integer keys rounded into their range, as an object array."""
        out = np.empty(self.X.shape, dtype=object)
        for j, integer in enumerate(self.integer):
            col = self.X[:, j]
            out[:, j] = ([int(v) for v in np.clip(np.rint(col), self.low[j], self.high[j])] if integer
                         else [float(v) for v in col])
        return out

    def point_keys(self, i: int, values: np.ndarray | None = None) -> dict[str, Any]:
        """Point ``i``'s condition keys: its index and its value of each key (from ``values`` or the design's own)."""
        vals = self.values() if values is None else values
        return {"point": i, **{n: vals[i, j] for j, n in enumerate(self.names)}}

    def spec(self) -> dict:
        """Everything but the matrix, as JSON-able values (what the store's design.json holds)."""
        return {"experiment": self.experiment, "method": self.method, "samples": self.samples,
                "second_order": self.second_order, "levels": self.levels, "seed": self.seed,
                "keys": self.keys, "names": self.names, "also": self.also, "low": self.low, "high": self.high,
                "integer": self.integer, "remainder": self.remainder, "outputs": self.outputs,
                "custom": self.custom, "salib": self.salib, "points": self.points}

    def frame(self) -> pd.DataFrame:
        """One row per point: ``point``, the raw draw ``NAME_raw`` and the value set, ``NAME``."""
        vals = self.values()
        df = pd.DataFrame({"point": np.arange(self.points, dtype=np.int64)})
        for j, n in enumerate(self.names):
            df[f"{n}_raw"] = self.X[:, j]
            df[n] = pd.Series(list(vals[:, j]), dtype="int64" if self.integer[j] else "float64")
        return df

    @classmethod
    def from_spec(cls, spec: dict, X: np.ndarray) -> Design:
        """The design back from its ``spec()`` (as the store's ``design.json`` holds it) and its matrix ``X``."""
        fields = {k: spec[k] for k in cls.__dataclass_fields__ if k != "X"}
        return cls(**fields, X=np.asarray(X, dtype=float))

    # settings that decide the matrix; outputs may change between sweep and analysis
    def _matrix_spec(self) -> dict:
        s = self.spec()
        for k in ("outputs", "custom", "salib"):
            s.pop(k)
        return s

    def extends(self, old: Design) -> bool:
        """Whether this design is ``old`` grown: the same settings but more base samples, and ``old``'s
        points first.  Saltelli's scheme on a Sobol' sequence has that property, so a study whose
        intervals came out too wide grows in place and reruns none of its points (their seeds follow
        the point's number); the matrices are compared, so a method without it is simply refused."""
        mine, theirs = self._matrix_spec(), old._matrix_spec()
        for s in (mine, theirs):
            s.pop("samples"), s.pop("points")
        return (mine == theirs and self.points > old.points
                and np.array_equal(self.X[:old.points], old.X))


# -------------------------------------------------------------------------------------- key paths
def _get(data: dict, path: str, where: str) -> tuple[bool, Any]:
    """(found, value) at a dotted path; a missing entry of a ``params`` table is (False, None)."""
    node: Any = data
    parts = path.split(".")
    for k, part in enumerate(parts):
        m = KEY_PART.match(part)
        if not m:
            raise ConfigError(f"{where}: {path!r} is not a key path (like payment.stake or swarm.groups[1].count)")
        name, index = m.group(1), m.group(2)
        if not isinstance(node, dict) or name not in node:
            if isinstance(node, dict) and k == len(parts) - 1 and k > 0 and parts[k - 1] == "params":
                return False, None
            allowed = ", ".join(sorted(node)) if isinstance(node, dict) else "none"
            raise ConfigError(f"{where}: unknown key {path!r}: no {name!r} here; allowed: {allowed}")
        node = node[name]
        if index is not None:
            if not isinstance(node, list) or int(index) >= len(node):
                raise ConfigError(f"{where}: {path!r}: index {index} out of range")
            node = node[int(index)]
    return True, node


def _kind(data: dict, path: str, where: str) -> bool:
    """Whether the key at ``path`` is an integer key; refuses keys that are not numbers."""
    found, value = _get(data, path, where)
    if not found:
        return False  # a behaviour's or scheme's parameter left at its default: a float
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{where}: {path!r} is not a numeric key (it holds {value!r}); only numbers "
                          f"can be sampled")
    return isinstance(value, int)


def apply(base: dict, design_keys: list[str], also: list[list[str]], remainder: str | None,
          values, where: str) -> dict:
    """A copy of ``base`` with each key (and the keys that follow it) set; then the remainder count."""
    data = copy.deepcopy(base)
    for key, follow, v in zip(design_keys, also, values):
        for path in (key, *follow):
            set_path(data, path, v, where)
    if remainder is not None:
        part = KEY_PART.match(remainder.split(".")[1])
        assert part is not None, remainder  # checked where the sweep was read
        k = int(part.group(2))
        others = sum(g["count"] for j, g in enumerate(data["swarm"]["groups"]) if j != k)
        data["swarm"]["groups"][k]["count"] = data["swarm"]["robots"] - others
    return data


# ------------------------------------------------------------------------------------------ checks
def _corners(d: int) -> list[tuple[int, ...]]:
    if d <= MAX_FULL_CORNERS:
        return list(itertools.product((0, 1), repeat=d))
    out = {(0,) * d, (1,) * d}
    for j in range(d):
        for end in (0, 1):
            for rest in (0, 1):
                c = [rest] * d
                c[j] = end
                out.add(tuple(c))
    return sorted(out)


def _check_both_kinds(cfg: Experiment, outputs: list[str], where: str) -> None:
    need = [o for o in outputs if o in NEEDS_BOTH]
    if not need:
        return
    known = behaviours()
    honest = sum(g.count for g in cfg.swarm.groups if known[g.behaviour].honest)
    byz = cfg.swarm.robots - honest
    if honest == 0 or byz == 0:
        raise ConfigError(f"{where}: the output(s) {', '.join(need)} compare honest and Byzantine robots, "
                          f"but this corner has {honest} honest and {byz} Byzantine robot(s); narrow the "
                          f"range of the count, or leave those outputs out")


def make_design(exp: Experiment, seed: int | None = None) -> Design:
    """The design of ``exp``'s ``[sweep.sample]``, checked at every corner, drawn by SALib."""
    assert exp.sweep is not None and exp.sweep.sample is not None, exp.name  # asked only of a sampled sweep
    sample: Sample = exp.sweep.sample
    master = exp.seed if seed is None else seed
    where = f"{exp.name}: sweep.sample"
    base = exp.model_dump(exclude={"sweep"})
    keys = list(sample.bounds)
    bounds = [sample.bound(k) for k in keys]
    names = [b.name or label(k) for k, b in zip(keys, bounds)]
    for n in names:
        if n in ("point", "experiment", "condition", "run", "seed") or n in BUILTIN_OUTPUTS:
            raise ConfigError(f"{where}.bounds: the column name {n!r} is taken; give the key a `name`")
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ConfigError(f"{where}.bounds: two keys would name the column {dupes[0]!r}; give one of them "
                          f"a name: {{ range = [low, high], name = \"...\" }}")
    integer = []
    for k, b in zip(keys, bounds):
        is_int = _kind(base, k, f"{where}.bounds")
        for other in b.also:
            if other in keys:
                raise ConfigError(f"{where}.bounds.{k}: also = {other!r} is sampled itself")
            if _kind(base, other, f"{where}.bounds.{k}.also") != is_int:
                raise ConfigError(f"{where}.bounds.{k}: also = {other!r} is not of the same type (integer or "
                                  f"not) as {k!r}")
        if is_int and not all(float(v).is_integer() for v in b.range):
            raise ConfigError(f"{where}.bounds.{k}: an integer key needs whole-number bounds, got {b.range}")
        integer.append(is_int)
    rem = sample.remainder
    if rem is not None:
        parts = rem.split(".")
        m = KEY_PART.match(parts[1]) if len(parts) == 3 else None
        if not (parts[0] == "swarm" and m and m.group(1) == "groups" and m.group(2) is not None
                and parts[2] == "count"):
            raise ConfigError(f"{where}.remainder: {rem!r} must be a group's count, like swarm.groups[0].count")
        _get(base, rem, f"{where}.remainder")
        if rem in keys or any(rem in b.also for b in bounds):
            raise ConfigError(f"{where}.remainder: {rem!r} is sampled itself")
    custom = {n: o.model_dump() for n, o in sample.custom.items()}
    low = [float(b.range[0]) for b in bounds]
    high = [float(b.range[1]) for b in bounds]
    also = [list(b.also) for b in bounds]
    for corner in _corners(len(keys)):
        vals = [int(high[j] if c else low[j]) if integer[j] else (high[j] if c else low[j])
                for j, c in enumerate(corner)]
        shown = ", ".join(f"{n} = {v}" for n, v in zip(names, vals))
        at = f"{where}: at the corner {shown}"
        data = apply(base, keys, also, rem, vals, at)
        try:
            cfg = validate(data, at)
        except ConfigError as exc:
            raise ConfigError(str(exc).replace("invalid experiment", "the bounds give an invalid experiment")
                              ) from None
        _check_both_kinds(cfg, sample.outputs, at)
    for name, o in custom.items():
        if o["column"] in ("experiment", "condition", "run", "seed", "point"):
            raise ConfigError(f"{where}.custom.{name}: column {o['column']!r} is not a measurement")
    from importlib.metadata import version

    d = Design(exp.name, sample.method, sample.samples, sample.second_order, sample.levels, int(master),
               keys, names, also, low, high, integer, rem, list(sample.outputs), custom, version("SALib"),
               X=np.empty((0, len(keys))))
    return Design.from_spec(d.spec(), draw(d))


def draw(d: Design) -> np.ndarray:
    """SALib's sample for the design's settings, seeded by its master seed."""
    import warnings

    from SALib.sample import latin, morris, sobol

    problem = d.problem()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning about the sample's balance means a design we refuse
        if d.method == "sobol":
            return sobol.sample(problem, d.samples, calc_second_order=d.second_order, seed=d.seed)
        if d.method == "morris":
            return morris.sample(problem, d.samples, num_levels=d.levels, seed=d.seed)
        return latin.sample(problem, d.samples, seed=d.seed)


def design_data(exp: Experiment, design: Design) -> list[tuple[dict[str, Any], dict]]:
    """(keys, configuration data) for every point of the design."""
    base = exp.model_dump(exclude={"sweep"})
    vals = design.values()
    out = []
    for i in range(design.points):
        out.append((design.point_keys(i, vals),
                    apply(base, design.keys, design.also, design.remainder, list(vals[i]),
                          f"{exp.name}: sweep.sample point {i}")))
    return out


# ------------------------------------------------------------------------------------------- store
def _paths(root: Path, experiment: str) -> tuple[Path, Path]:
    folder = Path(root) / "designs"
    return folder / f"{experiment}.json", folder / f"{experiment}.parquet"


def save(store, design: Design) -> None:
    """Keep the design in the store (matrix first, settings last); refuse a store whose design of the
    same experiment differs.  Call with the store's lock held."""
    def write_parquet_atomic(frame, path):  # with each column's unit and description (store.dictionary)
        write_atomic(path, lambda tmp: write_table("designs", frame, tmp))

    spec_path, matrix_path = _paths(store.root, design.experiment)
    if spec_path.exists():
        old = load(store.root, design.experiment)
        grown = design.extends(old)
        if not grown and (old._matrix_spec() != design._matrix_spec() or not np.array_equal(old.X, design.X)):
            diff = sorted(k for k, v in design._matrix_spec().items() if old._matrix_spec().get(k) != v)
            raise StoreError(f"{store.root}: holds a {old.method} design of {design.experiment} with other "
                             f"settings ({', '.join(diff) or 'another matrix'}); its runs would not fit this "
                             f"design (only a design whose first points are the stored ones, such as a Sobol' "
                             f"design with more samples, grows a store): use another --out")
        if old.spec() == design.spec():
            return
        if grown:  # the matrix first: a growth cut short before the settings is read as the old design
            write_parquet_atomic(design.frame(), matrix_path)
    else:
        spec_path.parent.mkdir(exist_ok=True)
        write_parquet_atomic(design.frame(), matrix_path)
    write_text_atomic(json.dumps(design.spec(), indent=2) + "\n", spec_path)


def designs(root) -> list[str]:
    """Experiments with a design in the store at ``root``."""
    folder = Path(root) / "designs"
    return sorted(p.stem for p in folder.glob("*.json")) if folder.exists() else []


def load(root, experiment: str) -> Design:
    """The design of ``experiment`` kept in the store at ``root``."""

    spec_path, matrix_path = _paths(root, experiment)
    try:
        spec = json.loads(spec_path.read_text())
        frame = pd.read_parquet(matrix_path)
    except (OSError, ValueError) as exc:
        raise StoreError(f"{root}: the design of {experiment} is unreadable ({exc})") from None
    X = frame[[f"{n}_raw" for n in spec["names"]]].to_numpy(dtype=float)
    if len(X) < spec["points"]:
        raise StoreError(f"{root}: the design of {experiment} has {len(X)} of its {spec['points']} points")
    # more rows than the settings name: a growth (``save``) stopped between its two writes
    return Design.from_spec(spec, X[:spec["points"]])
