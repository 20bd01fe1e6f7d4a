"""``[sweep.sample]``: a sampled design (Sobol', Morris, Latin hypercube) instead of a grid.

What can be checked without the rest of the experiment is checked here (the method's sample size,
empty or inverted ranges, output names); keys, integer types and the validity of the experiment at the
corners of the bounds need the whole experiment and are checked by ``runner.design`` before anything
runs.
"""
from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from ..errors import ConfigError

#: Outputs every design can name without defining them (one value per run; ``runner.design`` says how).
BUILTIN_OUTPUTS = {
    "items": "items collected by the whole swarm after the transitory period",
    "share_gap": "mean wealth share of an honest robot minus that of a Byzantine robot (percentage points)",
    "byzantine_share": "the Byzantine robots' total share of the swarm's wealth (%)",
}
STATS = ("sum", "mean", "median", "min", "max", "std")
#: RBD-FAST, the analysis of a Latin hypercube, uses this many harmonics and needs more samples than 2 M.
RBD_HARMONICS = 10


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Bound(_Strict):
    """A sampled key's range, with an optional column name and keys that take the same value."""

    range: list[Annotated[float, Field(allow_inf_nan=False)]] = Field(min_length=2, max_length=2)
    name: str | None = None
    also: list[str] = Field(default_factory=list)


class Output(_Strict):
    """A user output: ``stat`` of a robots-table ``column`` over the run's ``robots``."""

    column: str
    stat: Literal["sum", "mean", "median", "min", "max", "std"] = "mean"
    robots: Literal["all", "honest", "byzantine"] = "all"


class Sample(_Strict):
    """``[sweep.sample]``: a sampled design instead of a grid.

    ``method`` (sobol, morris or lhs) draws ``samples`` base samples over ``bounds`` (a range per key, or a
    ``Bound``); ``outputs`` are the per-run values whose indices are computed.
    """
    method: Literal["sobol", "morris", "lhs"]
    samples: Annotated[int, Field(gt=0, strict=True)]
    second_order: bool = True          # Sobol': also the second-order indices (N (2D + 2) points, else N (D + 2))
    levels: Annotated[int, Field(ge=2, strict=True)] = 4  # Morris: grid levels (even)
    remainder: str | None = None       # a group's count set to robots minus the other groups' counts
    outputs: list[str] = Field(default_factory=lambda: list(BUILTIN_OUTPUTS), min_length=1)
    custom: dict[str, Output] = Field(default_factory=dict)
    bounds: dict[str, list[Annotated[float, Field(allow_inf_nan=False)]] | Bound] = Field(min_length=1)

    def bound(self, key: str) -> Bound:
        """The bound of ``key`` as a ``Bound`` (a plain ``[low, high]`` range is wrapped into one)."""
        b = self.bounds[key]
        return b if isinstance(b, Bound) else Bound.model_construct(range=list(b), name=None, also=[])

    @model_validator(mode="after")
    def _usable(self) -> Sample:
        for key in self.bounds:
            r = self.bound(key).range
            if len(r) != 2:
                raise ConfigError(f"bounds.{key}: a range is [low, high], got {len(r)} number(s)")
            if not r[0] < r[1]:
                raise ConfigError(f"bounds.{key}: empty or inverted range [{r[0]}, {r[1]}]; "
                                 f"the low end must be below the high end")
        n, d = self.samples, len(self.bounds)
        if self.method == "sobol" and (n < 2 or n & (n - 1)):
            lower = 2 ** max(1, int(math.log2(n)))
            raise ConfigError(f"samples = {n}: Sobol' designs need a power of 2 (at least 2), e.g. {lower} or "
                             f"{2 * lower}")
        if self.method == "morris":
            if n < 2:
                raise ConfigError(f"samples = {n}: Morris needs at least 2 trajectories")
            if self.levels % 2:
                raise ConfigError(f"levels = {self.levels}: Morris needs an even number of levels")
        if self.method == "lhs" and n <= 2 * RBD_HARMONICS:
            raise ConfigError(f"samples = {n}: a Latin hypercube is analysed with RBD-FAST "
                             f"({RBD_HARMONICS} harmonics), which needs more than {2 * RBD_HARMONICS} samples")
        if self.method == "sobol" and d < 2:
            raise ConfigError("Sobol' indices need at least 2 sampled keys")
        for name in self.outputs:
            if name not in BUILTIN_OUTPUTS and name not in self.custom:
                raise ConfigError(f"outputs: unknown output {name!r}; built in: {', '.join(BUILTIN_OUTPUTS)}; "
                                 f"or define it under [sweep.sample.custom.{name}]")
        if len(set(self.outputs)) != len(self.outputs):
            raise ConfigError("outputs: an output is named twice")
        return self
