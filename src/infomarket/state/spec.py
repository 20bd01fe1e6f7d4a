"""What a piece of simulation state is: a field's name, dtype, shape, who writes it and what it means.

The engine's state is split by domain, each with its own ``Spec`` (the fields), builder and growth
function: parameters (``engine.params``), the swarm (``engine.swarm``), the ledger (``ledger.state``) and
the log (``state.log``).  The compiled step still receives one flat view of all of them (``state.view``);
the spec's ``writer`` decides how each field is typed there, and so who can write it:

``host``    set when the run is built, never changed: read-only in compiled code, for everyone.
``engine``  the swarm's state: written by the engine's step, and by buy rules through ``behaviours.api``.
``ledger``  the market's books (and the chain model's state, ``ledger.poa.spec``): read-only in
            compiled code except inside ledger operations (``ledger/``: the shared ``ledger.kernels`` and
            each ledger's own), which alone may ``unlock`` them.  A rule that writes ``balance`` does not
            compile.
``log``     outputs (events, payments, history, error bits, the clock): read-only except inside the
            engine's and the ledger's log operations.

Shapes are written with symbols: ``n`` robots, ``kn`` neighbour slots, ``kp`` pending slots, ``kt`` outcome
records, ``P`` the transaction pool, ``E`` the event log, ``S`` sites, ``K`` obstacles, ``m`` history rows;
``""`` is a scalar (the chain model's own symbols are listed in ``ledger.poa.spec``).
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from collections.abc import Iterable, Mapping

import numpy as np

from ..errors import InternalError

WRITERS = ("host", "engine", "ledger", "log")


@dataclass(frozen=True)
class Field:
    """One array (or scalar) of the state."""

    name: str
    dtype: str  # numpy dtype name, or 'float' / 'int' / 'bool' for a scalar
    shape: str  # comma-separated symbols, '' for a scalar
    writer: str
    doc: str

    @property
    def ndim(self) -> int:
        """The field's number of dimensions, from its shape text (0 for a scalar)."""
        return len(self.shape.split(",")) if self.shape else 0


class Spec:
    """The fields of one domain, in order; ``check`` verifies a built domain against them."""

    def __init__(self, domain: str, fields: Iterable[Field]):
        self.domain = domain
        self.fields = tuple(fields)
        for f in self.fields:
            if f.writer not in WRITERS:
                raise InternalError(f"{domain}.{f.name}: unknown writer {f.writer!r}")
        self.names = tuple(f.name for f in self.fields)
        self.tuple = namedtuple(domain.capitalize(), self.names)
        # what ``check`` compares, worked out once: every run's build checks every field
        self._expected = tuple((f, f.ndim, {"float": float, "int": int, "bool": bool}[f.dtype] if f.ndim == 0
                                else np.dtype(f.dtype)) for f in self.fields)

    def __iter__(self):
        return iter(self.fields)

    def __contains__(self, name: str) -> bool:
        return name in self.names

    def writer(self, name: str) -> str:
        """Who writes the field ``name`` (one of ``WRITERS``: the host, the engine, the ledger or the event log)."""
        return next(f.writer for f in self.fields if f.name == name)

    def check(self, values: Mapping) -> None:
        """Every field present, with its dtype and number of dimensions (a builder's contract)."""
        missing = [n for n in self.names if n not in values]
        if missing:
            raise InternalError(f"{self.domain}: missing {', '.join(missing)}")
        for f, ndim, kind in self._expected:
            v = values[f.name]
            if ndim == 0:
                if type(v) is not kind:
                    raise InternalError(f"{self.domain}.{f.name}: {type(v).__name__}, spec says {f.dtype}")
            elif not isinstance(v, np.ndarray) or v.dtype != kind or v.ndim != ndim:
                got = f"{v.dtype} {v.ndim}-d" if isinstance(v, np.ndarray) else type(v).__name__
                raise InternalError(f"{self.domain}.{f.name}: {got}, spec says {f.dtype} {ndim}-d")

    def build(self, values: Mapping):
        """The domain's named tuple from a mapping, checked against the spec."""
        self.check(values)
        return self.tuple(**{n: values[n] for n in self.names})

    def table(self) -> str:
        """Markdown table of the fields (docs and ``infomarket`` reference pages)."""
        rows = ["| field | dtype | shape | written by | meaning |", "|---|---|---|---|---|"]
        rows += [f"| `{f.name}` | {f.dtype} | [{f.shape}] | {f.writer} | {f.doc} |" for f in self.fields]
        return "\n".join(rows)


def fields(writer: str, dtype_shape_docs: Iterable[tuple[str, str, str, str]]) -> list[Field]:
    """Shorthand: rows of (name, dtype, shape, doc) that share a writer."""
    return [Field(name, dtype, shape, writer, doc) for name, dtype, shape, doc in dtype_shape_docs]
