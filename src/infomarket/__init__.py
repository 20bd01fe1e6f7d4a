"""infomarket: a swarm of foraging robots that buy and sell navigation information.

Quick use::

    import infomarket as im
    cfg = im.load_experiment("fig2B")
    res = im.simulate(cfg, seed=1)
    res.robots.groupby("honest").items_collected.median()

New behaviours and payment schemes: ``im.register_behaviour`` / ``im.register_payment`` (docs/extending.md).
"""
from ._version import __version__ as __version__  # written in _version.py only (pyproject.toml reads it)

# First: numba caches the package's own compiled functions by its source (compiled_cache), so each must be
# decorated after this.
from .compiled_cache import install as _install_compiled_cache

_install_compiled_cache()

from .config import Experiment, load_experiment  # noqa: E402 - after the compiled cache is installed
from .engine import Result, Simulation, simulate  # noqa: E402 - after the compiled cache is installed
from .errors import ConfigError, InfomarketError, SimulationError  # noqa: E402 - after the compiled cache is installed
from .registry import behaviour, payment, register_behaviour, register_payment  # noqa: E402 - after the compiled cache is installed
from . import builtins as _builtins  # noqa: E402, F401  (registers the built-in rules)
from .checks import explain as _explain  # noqa: E402 - after the compiled cache is installed
from .engine.simulation import explain_errors_with as _explain_errors_with  # noqa: E402 - after the compiled cache is installed

# An error raised inside the compiled step names the rule, its file and line, and the step, from the
# Python API as from the command line (the engine cannot import the checkers, which import it).
_explain_errors_with(_explain)

# Fix the digest of the code this process runs (kernels are cached by it), had nothing compiled been imported.
from .generated import freeze_package_digest as _freeze  # noqa: E402 - after every compiled module is imported

_freeze()

__all__ = ["ConfigError", "Experiment", "InfomarketError", "Result", "Simulation", "SimulationError",
           "behaviour", "load_experiment", "payment", "register_behaviour", "register_payment", "simulate"]
