"""Public checkers for rules: what every behaviour and payment scheme must satisfy.

Plugin authors run their rules through the same checks as the built-ins (the test suite runs them over
every registered rule): it compiles, same seed gives the same numbers, money is conserved, balances
never go negative, navigation tables stay finite.  A failed check raises ``CheckFailed`` saying which.
"""
from __future__ import annotations

import dataclasses
import traceback

import numba
import numpy as np

from .config import validate
from .engine.simulation import simulate
from .errors import InfomarketError
from .ledger import LedgerEvent, replay_events
from .ledger.replay import Ledger
from .payments import MARKETS, PAPER_STAKE
from .registry import get_behaviour, get_payment


class CheckFailed(InfomarketError, AssertionError):
    """A rule broke an invariant every rule must keep."""


def _swarm(behaviour: str, robots: int, scheme: str, stake: float, steps: int):
    half = robots // 2
    groups = [{"behaviour": "naive", "count": robots - half}, {"behaviour": behaviour, "count": half}]
    return validate({"steps": steps, "swarm": {"robots": robots, "groups": groups},
                     "payment": {"scheme": scheme, "stake": stake}}, f"check of {behaviour!r}")


def _invariants(res, what: str, initial: float, robots: int) -> None:
    deposits = int((res.events.kind == "deposit").sum())
    total = res.totals["wealth"] + res.totals["pots"] + res.totals["burned"]
    if not np.isclose(total, robots * initial + deposits * 1.0, rtol=0, atol=1e-9):
        raise CheckFailed(f"{what}: money not conserved ({total} != {robots * initial} + {deposits} rewards)")
    if (res.robots.wealth < -1e-12).any():
        raise CheckFailed(f"{what}: a balance went negative")
    if not np.isfinite(res.events[["direction_deg", "x", "y"]].to_numpy()).all():
        raise CheckFailed(f"{what}: a purchase carried a non-finite vector")


def _behaviour_bounds_checked(name: str, cfg, seed: int, steps: int) -> None:
    """Run ``name``'s buy and sell rules once per robot of that behaviour, compiled with numba's bounds
    checking, on the world of a short run of ``cfg``; an index out of range is a CheckFailed naming the
    rule, its file and the line (found by running the same call in plain Python)."""
    from .engine.simulation import Simulation

    spec = get_behaviour(name)
    sim = Simulation(cfg, seed)
    sim.step(max(1, min(steps, 500)))
    w, view = sim.world, sim._view
    kind = sim.kinds.index(name)
    rng = np.random.default_rng(seed)
    for role, rule in (("sell", spec.sell), ("buy", spec.buy)):
        py = rule.py_func
        try:
            checked = numba.njit(boundscheck=True)(py)
        except Exception:  # noqa: BLE001  (not compilable here: the runs report it)
            continue
        for me in np.flatnonzero(w.kind == kind):
            params = [float(w.bparams[me][spec.params.index(p)]) for p in rule.params]
            extra = ([rng] if rule.wants_rng else []) + params
            calls = ([(int(me), site) for site in (0, 1)] if role == "sell"
                     else [(int(me), np.array([j for j in range(w.kind.shape[0]) if j != me], np.int64))])
            for args in calls:
                try:
                    checked(view, *args, *extra)
                except (IndexError, ZeroDivisionError) as exc:
                    # plain Python on the world's arrays names the line
                    raise CheckFailed(f"behaviour {name!r}: its {role} rule "
                                      + _located(exc, py, lambda: py(w, *args, *extra))) from None


def check_behaviour(name: str, *, robots: int = 10, steps: int = 3000, seed: int = 0) -> None:
    """Run ``name`` among naive robots, with and without staking, twice each with the same seed; and its
    rules once each compiled with bounds checking (an index out of range is caught, named with the rule's
    file and line)."""
    get_behaviour(name)  # a clear ConfigError for an unknown name
    _behaviour_bounds_checked(name, _swarm(name, robots, *MARKETS["delayed"], steps), seed, steps)
    for scheme, stake in (MARKETS["delayed"], MARKETS["staking"]):
        cfg = _swarm(name, robots, scheme, stake, steps)
        a = simulate(cfg, seed, record_events=True)
        b = simulate(cfg, seed, record_events=True)
        what = f"behaviour {name!r} under {scheme} (stake {stake})"
        if not (a.robots.equals(b.robots) and a.events.equals(b.events)):
            raise CheckFailed(f"{what}: the same seed gave different results")
        _invariants(a, what, cfg.payment.initial_wealth, robots)


def _rule_where(func) -> tuple[str, int]:
    code = func.__code__
    return code.co_filename, code.co_firstlineno


def _failing_line(exc: BaseException, filename: str) -> int | None:
    """The line of ``filename`` where ``exc`` was raised (the innermost frame in that file), or None."""
    lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__) if f.filename == filename]
    return lines[-1] if lines else None


def _located(exc: BaseException, py, plain_call) -> str:
    """``NAME indexes an array out of bounds (...) at FILE:LINE`` for an error of the bounds-checked rule
    ``py``: numba's message names no line, so ``plain_call`` repeats the failing call in plain Python."""
    filename, first = _rule_where(py)
    line = None
    try:
        plain_call()
    except Exception as plain:  # noqa: BLE001  (only to locate the line)
        line = _failing_line(plain, filename)
    at = f"{filename}:{line}" if line else f"{filename}:{first} (the function)"
    what = "indexes an array out of bounds" if isinstance(exc, IndexError) else "divides by zero"
    return f"{py.__name__} {what} ({type(exc).__name__}: {exc}) at {at}"


def _replay(ledger: Ledger, events: list) -> None:
    for ev in events:
        if ev.kind == "deposit":
            ledger.deposit(ev.buyer)
        else:
            ledger.purchase(ev.buyer, ev.seller, ev.site, ev.direction_deg)


def _bounds_checked(name: str, events: list, robots: int, stake: float) -> None:
    """Replay ``events`` through scheme ``name`` with its weight rule compiled with numba's bounds checking
    (an index out of range raises instead of writing past the array), then, should it raise, through the
    rule's plain Python to find the line; raise CheckFailed naming the rule, its file and line."""
    spec = get_payment(name)
    rule = spec.weights
    py = rule.py_func
    try:
        checked = numba.njit(boundscheck=True)(py)
    except Exception:  # not a compilable function: the ordinary replay reports it
        return

    def ledger_with(func) -> Ledger:
        ledger = Ledger(robots, scheme=name, stake=stake)
        ledger.scheme = dataclasses.replace(spec, weights=dataclasses.replace(rule, func=func))
        return ledger

    try:
        _replay(ledger_with(checked), events)
    except (IndexError, ZeroDivisionError) as exc:
        raise CheckFailed(f"payment scheme {name!r}: its rule "
                          + _located(exc, py, lambda: _replay(ledger_with(py), events))) from None


def check_payment(name: str, *, robots: int = 6, sequences: int = 30, seed: int = 0) -> None:
    """Replay random purchases and deposits through scheme ``name``, with and without staking; the first
    sequences also with the rule compiled with bounds checking (an index out of range is caught, named
    with the rule's file and line, instead of writing past the array unnoticed)."""
    spec = get_payment(name)
    rng = np.random.default_rng(seed)
    for k in range(sequences):
        events = []
        for _ in range(int(rng.integers(1, 40))):
            buyer = int(rng.integers(robots))
            if rng.random() < 0.2:
                events.append(LedgerEvent("deposit", buyer))
            else:
                seller = (buyer + int(rng.integers(1, robots))) % robots
                events.append(LedgerEvent("purchase", buyer, seller, int(rng.integers(2)),
                                           float(rng.uniform(0, 360))))
        events.append(LedgerEvent("deposit", int(rng.integers(robots))))
        stake = PAPER_STAKE if k % 2 else 0.0
        if k < 2:
            _bounds_checked(spec.name, events, robots, stake)
        first = replay_events(events, robots, scheme=spec.name, stake=stake)
        again = replay_events(events, robots, scheme=spec.name, stake=stake)
        what = f"payment scheme {name!r} (sequence {k}, stake {stake})"
        if not np.array_equal(first.balances, again.balances):
            raise CheckFailed(f"{what}: the same events gave different balances")
        deposits = sum(e.kind == "deposit" for e in events)
        if not np.isclose(first.balances.sum() + first.pots.sum(), robots + deposits, rtol=0, atol=1e-9):
            raise CheckFailed(f"{what}: money not conserved")
        if (first.balances < -1e-12).any():
            raise CheckFailed(f"{what}: a balance went negative")
