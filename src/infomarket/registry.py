"""Registry of market rules: behaviours (a buy rule and a sell rule) and payment schemes.

A rule is a plain Python function over the world tuple, robot ids and numbers, written in the
numba-compatible subset.  Registering it wraps it in ``numba.njit`` (``infomarket.jit``); the engine then generates a
step kernel that calls the configured rules directly (see ``engine.specialise``), so a user's rule
runs at the same compiled speed as the built-ins, which are registered through this very module.

Rule parameters are the function's arguments after the fixed leading ones; their defaults are the
defaults of the behaviour or scheme, and an experiment file may override them by name.
"""
from __future__ import annotations

import inspect
import math
import re
from dataclasses import dataclass, field
from collections.abc import Callable

from ._numba_internals import CPUDispatcher
from .compiled_cache import in_package
from .errors import ConfigError, RegistrationError, RuleError
from .jit import njit

#: Fixed leading arguments of each kind of rule (everything after them is a parameter).
BUY_ARGS = ("w", "me", "nbrs")
SELL_ARGS = ("w", "me", "site")
PAY_ARGS = ("buyer", "sellers", "sites", "directions", "weights")


@dataclass(frozen=True)
class Rule:
    """One compiled rule and the numeric parameters it takes, in call order."""

    func: Callable
    params: tuple[str, ...]
    defaults: dict[str, float]
    wants_rng: bool = False  #: the rule takes the run's numpy Generator as ``rng`` after the fixed arguments
    #: a payment rule that takes ``market`` (the world, to read with ``behaviours.market``) after the fixed ones
    wants_market: bool = False

    @property
    def py_func(self) -> Callable:
        """The rule's plain Python function (numba keeps it as ``py_func``), for reading its source and running it
        uncompiled."""
        return getattr(self.func, "py_func", self.func)


class _Limited:
    """A rule's spec whose parameters have limits: ``check`` says why a value is not allowed."""

    limits: dict[str, tuple[str, Callable[[float], bool]]]

    def check(self, name: str, value: float) -> str | None:
        """Why ``value`` is not allowed for parameter ``name``, or None."""
        if name in self.limits:
            text, ok = self.limits[name]
            if not ok(value):
                return f"must be {text}"
        return None


@dataclass(frozen=True)
class BehaviourSpec(_Limited):
    """A robot behaviour: what it buys (and how it uses it) and what it sells."""

    name: str
    buy: Rule
    sell: Rule
    honest: bool
    description: str = ""
    params: tuple[str, ...] = field(default=())
    defaults: dict[str, float] = field(default_factory=dict)
    limits: dict[str, tuple[str, Callable[[float], bool]]] = field(default_factory=dict)
    #: Its robots keep waypoint paths (``behaviours.paths``): runs with it compile the step's paths
    #: variant (``engine.step``, ``engine.paths``), which dead-reckons and follows paths, even on the plane.
    paths: bool = False
    #: Its buy rule reads and writes nothing for a robot without a neighbour (it only walks ``nbrs``), so
    #: the step does not call it for one.  Off, it is called for every robot out of cooldown every step.
    needs_neighbours: bool = False


@dataclass(frozen=True)
class PaymentSpec(_Limited):
    """A payment scheme: how the shared reward (plus stakes) is split among a round trip's sellers."""

    name: str
    weights: Rule
    description: str = ""
    limits: dict[str, tuple[str, Callable[[float], bool]]] = field(default_factory=dict)

    @property
    def params(self) -> tuple[str, ...]:
        """The scheme's parameter names, in call order (those of its weights rule)."""
        return self.weights.params

    @property
    def defaults(self) -> dict[str, float]:
        """The scheme's parameter defaults by name (an experiment's ``payment_params`` overrides them)."""
        return self.weights.defaults


_BEHAVIOURS: dict[str, BehaviourSpec] = {}
_PAYMENTS: dict[str, PaymentSpec] = {}


def _jit(func: Callable) -> Callable:
    if isinstance(func, CPUDispatcher):
        return func
    if not inspect.isfunction(func):  # a builtin, a class, a number...: numba compiles only Python functions
        raise RuleError(f"a rule must be a Python function (def ...), got {_shown(func)}")
    return njit(func, cache=in_package(func))


#: What a behaviour's or a payment scheme's name may be: it is written in experiment files, stored in the
#: results' columns and printed, so a word of letters, digits and underscores.
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _check_registration(what: str, name, description, limits, params: tuple[str, ...], user_limits) -> None:
    """RegistrationError for a name, description or limits that cannot be registered."""
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise RegistrationError(f"{what} name {_shown(name)}: a name is 1 to 64 letters, digits or underscores, "
                                f"not starting with a digit (it is written in experiment files and results)")
    if not isinstance(description, str):
        raise RegistrationError(f"{what} {name!r}: description must be text, got {_shown(description)}")
    if user_limits is None:
        return
    if not isinstance(user_limits, dict):
        raise RegistrationError(f"{what} {name!r}: limits must be a dict of parameter -> (text, predicate), "
                                f"got {_shown(user_limits)}")
    for key, value in user_limits.items():
        if key not in params:
            raise RegistrationError(f"{what} {name!r}: limits name {key!r}, which is not one of its parameters "
                                    f"({', '.join(params) or 'none'})")
        if not (isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], str) and callable(value[1])):
            raise RegistrationError(f"{what} {name!r}: the limit of {key!r} must be (text, predicate), e.g. "
                                    f"(\"> 0\", lambda v: v > 0); got {_shown(value)}")


def _where(func: Callable) -> str:
    """``file.py:12``: where a rule is defined, for messages."""
    code = getattr(func, "__code__", None)
    return f"{code.co_filename}:{code.co_firstlineno}" if code is not None else "unknown file"


def _rule(func: Callable, fixed: tuple[str, ...], what: str, market: bool = False) -> Rule:
    jitted = _jit(func)
    py = getattr(jitted, "py_func", jitted)
    sig = list(inspect.signature(py).parameters.values())
    where = _where(py)
    if len(sig) < len(fixed):
        raise RuleError(f"{what} {py.__name__} ({where}) must take the arguments {', '.join(fixed)} first; "
                        f"it takes ({', '.join(p.name for p in sig)})")
    for want, p in zip(fixed, sig):
        if p.name != want or p.default is not p.empty or p.kind not in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD):
            raise RuleError(f"{what} {py.__name__} ({where}) must take the arguments {', '.join(fixed)} first, "
                            f"without defaults; it takes ({', '.join(p.name for p in sig)}): argument "
                            f"{sig.index(p) + 1} is {p.name!r}, not {want!r}")
    extra = sig[len(fixed):]
    wants_market = market and bool(extra) and extra[0].name == "market"
    if wants_market:
        extra = extra[1:]
    wants_rng = bool(extra) and extra[0].name == "rng"
    if wants_rng:
        extra = extra[1:]
    for p in extra:
        if p.kind not in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD):
            raise RuleError(f"{what} {py.__name__}: parameter {p.name} must be a plain positional argument")
    for p in extra:  # parameters are numbers (the world holds them as float64)
        if p.default is not p.empty and (isinstance(p.default, bool) or not isinstance(p.default, (int, float))
                                         or not math.isfinite(p.default)):
            raise RuleError(f"{what} {py.__name__} ({where}): parameter {p.name!r} has the default "
                            f"{p.default!r}; rule parameters are numbers (floats), so a default must be a finite "
                            f"number such as 0.0")
    defaults = {p.name: float(p.default) for p in extra if p.default is not p.empty}
    return Rule(jitted, tuple(p.name for p in extra), defaults, wants_rng, wants_market)


def register_behaviour(name: str, *, buy: Callable | str, sell: Callable | str, honest: bool,
                       description: str = "", limits: dict | None = None,
                       replace: bool = False, paths: bool = False,
                       needs_neighbours: bool = False) -> BehaviourSpec:
    """Register a behaviour from a buy rule and a sell rule (functions, or names of registered behaviours
    whose rule to reuse).

    ``buy(w, me, nbrs, *params)`` buys from the neighbours ``nbrs`` (ids, increasing) and installs what it
    buys; ``sell(w, me, site, *params) -> (valid, x, y, age)`` is the offer for ``site`` (0 food, 1 nest)
    in the seller's own frame.  A rule whose first argument after the fixed ones is named ``rng`` gets
    the run's numpy Generator there (so a random rule stays reproducible from the run's seed).  ``honest`` says
    whether robots of this behaviour count as honest in the
    metrics (Byzantine otherwise).  ``limits`` maps a parameter to ``(text, predicate)``, e.g.
    ``{"threshold": ("> 0", lambda v: v > 0)}``: configurations breaking it are rejected with the text.
    ``paths=True`` says the rules buy or install waypoint paths (``behaviours.paths``); runs with such a
    behaviour then compile the step's paths variant (``engine.step``, ``engine.paths``); other runs never pay for it.
    ``needs_neighbours=True`` says the buy rule does nothing for a robot without a neighbour (no write, no
    draw: it only walks ``nbrs``), so the step skips the call for such a robot; a reused buy rule keeps
    its behaviour's setting.
    """
    _check_registration("behaviour", name, description, None, (), None)
    if name in _BEHAVIOURS and not replace:
        raise RegistrationError(f"behaviour {name!r} is already registered (pass replace=True to override)")
    if not isinstance(honest, bool):
        raise RegistrationError(f"behaviour {name!r}: honest must be True or False, got {_shown(honest)}")
    for role, r in (("buy", buy), ("sell", sell)):
        if isinstance(r, str) and r not in _BEHAVIOURS:
            raise RegistrationError(f"behaviour {name!r}: {role}={r!r} names no registered behaviour (whose "
                                    f"{role} rule it would reuse); registered: {', '.join(_BEHAVIOURS)}")
    buy_rule = _BEHAVIOURS[buy].buy if isinstance(buy, str) else _rule(buy, BUY_ARGS, "buy rule")
    sell_rule = _BEHAVIOURS[sell].sell if isinstance(sell, str) else _rule(sell, SELL_ARGS, "sell rule")
    params: list[str] = []
    defaults: dict[str, float] = {}
    for rule in (buy_rule, sell_rule):
        for p in rule.params:
            if p not in params:
                params.append(p)
        for k, v in rule.defaults.items():
            if k in defaults and defaults[k] != v:
                raise RegistrationError(f"behaviour {name!r}: rules disagree on the default of {k!r}")
            defaults[k] = v
    _check_registration("behaviour", name, description, limits, tuple(params), limits)
    limits = dict(limits or {})
    for r in (buy, sell):
        if isinstance(r, str):  # a reused rule brings its limits along
            limits = {**_BEHAVIOURS[r].limits, **limits}
    limits = {k: v for k, v in limits.items() if k in params}
    if any(isinstance(r, str) and _BEHAVIOURS[r].paths for r in (buy, sell)):
        paths = True  # a reused path rule needs the step that keeps paths
    if not isinstance(needs_neighbours, bool):
        raise RegistrationError(f"behaviour {name!r}: needs_neighbours must be True or False, got "
                                f"{_shown(needs_neighbours)}")
    if isinstance(buy, str):
        needs_neighbours = needs_neighbours or _BEHAVIOURS[buy].needs_neighbours  # the same buy rule
    spec = BehaviourSpec(name, buy_rule, sell_rule, bool(honest), description, tuple(params), defaults, limits,
                         bool(paths), needs_neighbours)
    _BEHAVIOURS[name] = spec
    return spec


def behaviour(name: str, *, buy: Callable | str, honest: bool, description: str = "", limits: dict | None = None,
              replace: bool = False, paths: bool = False, needs_neighbours: bool = False):
    """Decorator form of :func:`register_behaviour` for the sell rule: ``@behaviour("liar", buy="naive",
    honest=False)`` over ``def sell(w, me, site): ...``; ``limits``, ``paths`` and ``needs_neighbours`` as
    there."""

    def wrap(sell: Callable) -> Callable:
        spec = register_behaviour(name, buy=buy, sell=sell, honest=honest, description=description,
                                  limits=limits, replace=replace, paths=paths, needs_neighbours=needs_neighbours)
        return spec.sell.func

    return wrap


def register_payment(name: str, weights: Callable, *, description: str = "", limits: dict | None = None,
                     replace: bool = False) -> PaymentSpec:
    """Register a payment scheme from its weight rule.

    ``weights(buyer, sellers, sites, directions, weights, *params)`` receives the buyer's transactions
    since its last deposit (seller id, site, direction in degrees in the buyer's frame) and fills
    ``weights`` with one non-negative number per transaction.  On a deposit the ledger pays the buyer the
    reward and its pot of stakes, then moves ``information_share * reward + pot`` from the buyer to the
    sellers in proportion to those weights, so every scheme conserves money by construction.
    A rule whose first argument after the fixed ones is named ``market`` receives the world there, to
    read (never write) every robot's wealth and reputation record with ``infomarket.behaviours.market``;
    ``rng``, if wanted, comes next.
    """
    _check_registration("payment scheme", name, description, None, (), None)
    if name in _PAYMENTS and not replace:
        raise RegistrationError(f"payment scheme {name!r} is already registered (pass replace=True to override)")
    rule = _rule(weights, PAY_ARGS, "payment rule", market=True)
    _check_registration("payment scheme", name, description, limits, rule.params, limits)
    spec = PaymentSpec(name, rule, description, dict(limits or {}))
    _PAYMENTS[name] = spec
    return spec


def payment(name: str, *, description: str = "", limits: dict | None = None, replace: bool = False):
    """Decorator form of :func:`register_payment` (``limits`` as there)."""

    def wrap(weights: Callable) -> Callable:
        return register_payment(name, weights, description=description, limits=limits,
                                replace=replace).weights.func

    return wrap


_ENTRY_POINTS_LOADED: list[bool] = []


def _load_entry_points() -> None:
    """Load third-party rules from the "infomarket.plugins" entry-point group, once.  (The built-ins
    are registered by ``infomarket.builtins``, which the package imports; this module never does.)"""
    if not _ENTRY_POINTS_LOADED:
        _ENTRY_POINTS_LOADED.append(True)
        from importlib.metadata import entry_points

        for ep in entry_points(group="infomarket.plugins"):
            ep.load()


def get_behaviour(name: str) -> BehaviourSpec:
    """The registered behaviour called ``name`` (plug-ins' entry points are loaded first).

    Args:
        name: the name it was registered under, as an experiment file writes it.

    Returns:
        Its spec: the compiled buy and sell rules, their parameters and whether the robot is honest.

    Raises:
        ConfigError: no behaviour has that name (the message lists those that do).

    Example:
        >>> from infomarket.registry import get_behaviour
        >>> spec = get_behaviour("sceptical")
        >>> spec.honest
        True
    """
    _load_entry_points()
    try:
        return _BEHAVIOURS[name]
    except KeyError:
        raise ConfigError(f"unknown behaviour {name!r}; registered: {', '.join(sorted(_BEHAVIOURS))}") from None


def get_payment(name: str) -> PaymentSpec:
    """The registered payment scheme called ``name`` (plug-ins' entry points are loaded first).

    Args:
        name: the name it was registered under, as an experiment file's ``payment`` writes it.

    Returns:
        Its spec: the compiled weights rule, its parameters and their defaults.

    Raises:
        ConfigError: no scheme has that name (the message lists those that do).

    Example:
        >>> from infomarket.registry import get_payment
        >>> get_payment("outlier").defaults
        {'theta': 30.0}
    """
    _load_entry_points()
    try:
        return _PAYMENTS[name]
    except KeyError:
        raise ConfigError(f"unknown payment scheme {name!r}; registered: {', '.join(sorted(_PAYMENTS))}") from None


def behaviours() -> dict[str, BehaviourSpec]:
    """Every registered behaviour by name: the built-ins, plug-ins' and those this process registered.

    A copy, so a caller cannot register or remove one by editing it.

    Example:
        >>> from infomarket.registry import behaviours
        >>> "naive" in behaviours() and "saboteur" in behaviours()
        True
    """
    _load_entry_points()
    return dict(_BEHAVIOURS)


def payments() -> dict[str, PaymentSpec]:
    """Every registered payment scheme by name (a copy; see ``behaviours``).

    Example:
        >>> from infomarket.registry import payments
        >>> "outlier" in payments()
        True
    """
    _load_entry_points()
    return dict(_PAYMENTS)


def rule_function(kind: str, name: str, role: str) -> Callable:
    """The compiled function of a registered rule; generated kernels look their rules up here."""
    if kind == "behaviour":
        return getattr(get_behaviour(name), role).func
    return get_payment(name).weights.func
