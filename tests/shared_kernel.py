"""One step kernel for the many small behaviour mixes the tests run.

A step kernel is compiled per behaviour mix (in kind order), payment scheme and step variant, which on a
cold cache costs more than most tests' own work.  Tests that run built-in behaviours side by side run them
on a kernel compiled for every built-in behaviour instead (``Simulation``'s ``kernel_kinds``: the same rules
are called, so the run is the same; ``tests/test_checks.py`` checks it), the kernel the rule checks compile
anyway: the suite compiles one such kernel per payment scheme and step variant, not one per mix.
"""
from __future__ import annotations

from infomarket.engine.params import behaviour_kinds
from infomarket.engine.simulation import Result, Simulation, as_experiment
from infomarket.engine.specialise import uses_paths
from infomarket.registry import behaviours, get_behaviour

#: The built-in behaviours, taken when this module is first imported (tests/conftest.py imports it before any
#: test registers a rule), so every test process names the same kernel.
BUILTIN = tuple(sorted(behaviours()))


def shared_kinds(cfg) -> tuple[str, ...] | None:
    """The shared kernel's behaviours for a run of ``cfg``: naive, then every built-in behaviour that keeps
    waypoint paths on or off as ``cfg``'s do (paths select another step), sorted; None (its own kernel)
    when ``cfg`` runs a behaviour that is not built in."""
    own = behaviour_kinds(cfg)
    if not set(own) <= set(BUILTIN):
        return None
    paths = uses_paths(own)
    return ("naive", *sorted(({b for b in BUILTIN if get_behaviour(b).paths == paths} | set(own)) - {"naive"}))


def simulation(cfg, seed: int, **kwargs) -> Simulation:
    """``Simulation(cfg, seed, **kwargs)`` on the shared kernel."""
    cfg = as_experiment(cfg)
    return Simulation(cfg, seed, kernel_kinds=shared_kinds(cfg), **kwargs)


def simulate(cfg, seed: int, **kwargs) -> Result:
    """``infomarket.simulate(cfg, seed, **kwargs)`` (a whole run) on the shared kernel."""
    return simulation(cfg, seed, **kwargs).run()
