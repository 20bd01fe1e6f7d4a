"""Public checkers for rules: what every behaviour and payment scheme must satisfy.

Plugin authors run their rules through the same checks as the built-ins (the test suite runs them over
every registered rule): it compiles, same seed gives the same numbers, money is conserved, balances
never go negative, navigation tables stay finite.  A failed check raises ``CheckFailed`` saying which.
"""
from __future__ import annotations

import dataclasses
import traceback
from typing import Any

import numba
import numpy as np

from .config import validate
from .engine.compiling import quiet_compiles
from .engine.simulation import Simulation
from .errors import InfomarketError, RuleRunError
from .jit import njit
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


#: Each rule compiled with bounds checking, once per process (many behaviours share a rule).
_BOUNDS_CHECKED: dict = {}


def _with_bounds_check(py):
    """``py`` compiled with numba's bounds checking (one dispatcher per function, so a rule shared by many
    behaviours compiles once), or None where it does not compile here (the runs report it)."""
    if py not in _BOUNDS_CHECKED:
        try:
            _BOUNDS_CHECKED[py] = njit(boundscheck=True)(py)
        except Exception:  # noqa: BLE001 - where it does not compile here, the runs report it
            _BOUNDS_CHECKED[py] = None
    return _BOUNDS_CHECKED[py]


def _behaviour_bounds_checked(name: str, cfg, seed: int, steps: int, kinds) -> None:
    """Run ``name``'s buy and sell rules once per robot of that behaviour, compiled with numba's bounds
    checking, on the world of a short run of ``cfg``; an index out of range is a CheckFailed naming the
    rule, its file and the line (found by running the same call in plain Python)."""
    spec = get_behaviour(name)
    sim = Simulation(cfg, seed, kernel_kinds=kinds)
    sim.step(max(1, min(steps, 500)))
    w, view = sim.world, sim._view
    kind = sim.kinds.index(name)
    rng = np.random.default_rng(seed)
    for role, rule in (("sell", spec.sell), ("buy", spec.buy)):
        py = rule.py_func
        checked = _with_bounds_check(py)
        if checked is None:
            continue
        for me in np.flatnonzero(w.kind == kind):
            params = [float(w.bparams[me][spec.params.index(p)]) for p in rule.params]
            extra = ([rng] if rule.wants_rng else []) + params
            calls = ([(int(me), site) for site in (0, 1)] if role == "sell"
                     else [(int(me), np.array([j for j in range(w.kind.shape[0]) if j != me], np.int64))])
            for args in calls:
                try:
                    with quiet_compiles():  # the first call compiles the rule
                        checked(view, *args, *extra)
                except (IndexError, ZeroDivisionError) as exc:
                    # plain Python on the world's arrays names the line
                    raise CheckFailed(f"behaviour {name!r}: its {role} rule "
                                      + _located(exc, py, lambda: py(w, *args, *extra))) from None  # noqa: B023 - called at once


def _kernel_kinds(name: str, alongside) -> tuple[str, ...]:
    """The behaviours of the kernel that checks ``name``: naive, then ``name`` and those ``alongside`` that
    keep waypoint paths on or off as ``name`` does (paths select another step), in sorted order, so every
    check given the same ``alongside`` runs on one kernel."""
    paths = get_behaviour(name).paths
    same = {b for b in alongside if get_behaviour(b).paths == paths} | {name}
    return ("naive", *sorted(same - {"naive"}))


def check_behaviour(name: str, *, robots: int = 10, steps: int = 3000, seed: int = 0, alongside=()) -> None:
    """Run ``name`` among naive robots, with and without staking, twice each with the same seed; and its
    rules once each compiled with bounds checking (an index out of range is caught, named with the rule's
    file and line).  ``alongside``: more behaviours to compile into the step kernel, so that checks of many
    behaviours, each given them all, compile one kernel per scheme instead of one per behaviour; the runs
    are the same (``Simulation``'s ``kernel_kinds``)."""
    get_behaviour(name)  # a clear ConfigError for an unknown name
    kinds = _kernel_kinds(name, alongside) if alongside else None
    _behaviour_bounds_checked(name, _swarm(name, robots, *MARKETS["delayed"], steps), seed, steps, kinds)
    for scheme, stake in (MARKETS["delayed"], MARKETS["staking"]):
        cfg = _swarm(name, robots, scheme, stake, steps)
        a = Simulation(cfg, seed, record_events=True, kernel_kinds=kinds).run()
        b = Simulation(cfg, seed, record_events=True, kernel_kinds=kinds).run()
        what = f"behaviour {name!r} under {scheme} (stake {stake})"
        if not (a.robots.equals(b.robots) and a.events.equals(b.events)):
            raise CheckFailed(f"{what}: the same seed gave different results")
        _invariants(a, what, cfg.payment.initial_wealth, robots)


def check_behaviours(names, **kwargs) -> None:
    """``check_behaviour`` for each of ``names``, all on one kernel per scheme (two for those with waypoint
    paths): a cold check of many behaviours compiles a few kernels, not two per behaviour.  An error other
    than a failed check (a rule that keeps the shared kernel from compiling need not be the checked
    behaviour's, so it may go unnamed) checks each behaviour alone, which names the rule at fault."""
    names = list(names)
    try:
        for name in names:
            check_behaviour(name, alongside=names, **kwargs)
    except CheckFailed:
        raise
    except Exception:
        for name in names:
            check_behaviour(name, **kwargs)
        raise


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
        checked = njit(boundscheck=True)(py)
    except Exception:  # noqa: BLE001 - not a compilable function: the ordinary replay reports it
        return

    def ledger_with(func) -> Ledger:
        ledger = Ledger(robots, scheme=name, stake=stake)
        ledger.scheme = dataclasses.replace(spec, weights=dataclasses.replace(rule, func=func))
        return ledger

    try:
        with quiet_compiles():  # the first call compiles the rule
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


# ------------------------------------------------------------------ explaining a run that failed
#: What each kind of rule returns, for messages, and how many values (None: nothing).
_RETURNS = {"sell": (4, "(valid, x, y, age)"), "buy": (None, "nothing"),
            "weights": (None, "nothing (it fills weights)")}


def _config_rules(cfg, kinds) -> list[tuple[str, str, Any, Any]]:
    """(owner, role, Rule, spec) of every rule a run of ``cfg`` calls: each behaviour's sell and buy
    rules (in kind order), then the scheme's weight rule."""
    out: list[tuple[str, str, Any, Any]] = []
    for role in ("sell", "buy"):  # the step's order: every offer, then every purchase
        for name in kinds:
            spec = get_behaviour(name)
            out.append((f"behaviour {name!r}", role, getattr(spec, role), spec))
    pay = get_payment(cfg.payment.scheme)
    out.append((f"payment scheme {cfg.payment.scheme!r}", "weights", pay.weights, pay))
    return out


def _calls(sim, role: str, rule, spec):
    """Every call the step would make of ``rule`` on the world of ``sim`` now: (label, compiled args,
    plain-Python args), in the step's order."""
    w, view = sim.world, sim._view
    rng = [sim.rng] if rule.wants_rng else []
    if role in ("sell", "buy"):
        kind = sim.kinds.index(spec.name)
        for me in (int(i) for i in np.flatnonzero(w.kind == kind)):
            params = [float(w.bparams[me][spec.params.index(p)]) for p in rule.params]
            if role == "sell":
                for site in (0, 1):
                    yield f"robot {me}, site {site}", (view, me, site, *rng, *params), (w, me, site, *rng, *params)
            else:
                nbrs = np.array(w.nbr[me, :w.nbr_count[me]], np.int64)
                yield f"robot {me}", (view, me, nbrs, *rng, *params), (w, me, nbrs, *rng, *params)
        return
    params = [float(w.pparams[spec.params.index(p)]) for p in rule.params]
    for buyer in (int(b) for b in np.flatnonzero(w.tx_count > 0)):
        a, b = int(w.tx_off[buyer]), int(w.tx_off[buyer] + w.tx_count[buyer])
        arrays = (w.tx_seller[a:b].copy(), w.tx_site[a:b].copy(), w.tx_dir[a:b].copy())
        weights = np.zeros(b - a)
        yield (f"buyer {buyer}", (buyer, *arrays, weights, *([view] if rule.wants_market else []), *rng, *params),
               (buyer, *arrays, weights.copy(), *([w] if rule.wants_market else []), *rng, *params))


def _where_line(py, plain_call) -> str:
    """``FILE:LINE`` of the line of ``py`` that raises when ``plain_call`` repeats the call in plain Python
    (numpy floating-point errors raised), else ``FILE:FIRST (the function)``."""
    filename, first = _rule_where(py)
    line = None
    try:
        with np.errstate(all="raise"):
            plain_call()
    except Exception as plain:  # noqa: BLE001  (only to locate the line)
        line = _failing_line(plain, filename)
    return f"{filename}:{line}" if line else f"{filename}:{first} (the function)"


def explain_run_failure(cfg, seed: int, exc: BaseException, step: int, *, record_events: bool = False,
                        history_every: int | None = None) -> str | None:
    """Which rule raised ``exc`` at ``step`` of the run of ``cfg`` with ``seed``: the run is repeated
    (compiled) up to the step before, then every rule the step calls is called on that world as the step
    calls it, in the step's order (sell, buy, weights); the first that raises the same kind of error is
    named with its file and line (from the same call in plain Python).  None when none does alone."""
    try:
        sim = Simulation(cfg, seed, record_events=record_events, history_every=history_every)
        if step > 1:
            sim.step(step - 1)
        sim.world.clock[0] = step  # the loop counts the step before it calls a rule
    except Exception:  # noqa: BLE001  (failed before the step: nothing to explain with)
        return None
    for owner, role, rule, spec in _config_rules(cfg, sim.kinds):
        for label, args, plain in _calls(sim, role, rule, spec):
            try:
                rule.func(*args)
            except type(exc) as again:
                py = rule.py_func
                at = _where_line(py, lambda: py(*plain))  # noqa: B023 - called at once
                what = "sell" if role == "sell" else "buy" if role == "buy" else "weight"
                return (f"{owner}: its {what} rule {py.__name__} raised {type(exc).__name__} "
                        f"({_short(again)}) at step {step} ({label}), at {at}")
            except Exception:  # noqa: BLE001  (another error: not the one the run met)
                continue
    return None


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:300] if text else "no message"


def explain_compile_failure(cfg, exc: BaseException) -> str | None:
    """Which rule makes the step kernel of ``cfg`` fail to compile (``exc``, numba's error, points into
    the generated kernel): each rule is compiled alone with the argument types the step passes; the first
    that does not compile, or returns what its kind of rule must not (a sell rule returns four values), is
    named with its file.  None when every rule compiles alone and returns what it must."""
    # the engine is imported on a failure only: the checker's own import stays light
    from .engine.build import build_world
    from .engine.params import behaviour_kinds
    from .engine.world import kernel_view

    class _Probe:  # the few attributes _calls reads
        rng: np.random.Generator
        kinds: tuple[str, ...]
        world: Any
        _view: Any

    try:
        probe = _Probe()
        probe.rng = np.random.default_rng(0)
        probe.kinds = behaviour_kinds(cfg)
        probe.world, _ = build_world(cfg, probe.rng, record_events=False, history_every=0)
        probe._view = kernel_view(probe.world)
    except Exception:  # noqa: BLE001 - a repeat that cannot start: the run's last step is the best known
        return None
    w = probe.world
    for owner, role, rule, spec in _config_rules(cfg, probe.kinds):
        py = rule.py_func
        where = _where(py)
        if role == "weights":  # one transaction, typed as the ledger passes them
            arrays = (np.zeros(1, w.tx_seller.dtype), np.zeros(1, w.tx_site.dtype), np.zeros(1, w.tx_dir.dtype))
            params = [0.0] * len(rule.params)
            args = (0, *arrays, np.zeros(1), *([probe._view] if rule.wants_market else []),
                    *([probe.rng] if rule.wants_rng else []), *params)
        else:
            kind = probe.kinds.index(spec.name)
            me = int(np.flatnonzero(w.kind == kind)[0])
            args = next(iter(_calls(probe, role, rule, spec)))[1]
            if role == "buy":
                args = (args[0], me, np.zeros(0, np.int64), *args[3:])
        what = {"sell": "sell rule", "buy": "buy rule", "weights": "weight rule"}[role]
        try:
            sig = tuple(numba.typeof(a) for a in args)
            rule.func.compile(sig)
            ret = rule.func.overloads[sig].signature.return_type
        except Exception as failed:  # noqa: BLE001 - any error compiling the rule alone is the rule's, reported by name
            lines = [ln for ln in str(failed).splitlines() if ln.strip() and "During:" not in ln]
            return f"{owner}: its {what} {py.__name__} ({where}) does not compile: " + " | ".join(lines[:6])
        count, shape = _RETURNS[role]
        n = getattr(ret, "count", None) if isinstance(ret, numba.types.BaseTuple) else None
        if count is not None and n != count:
            got = f"{n} values ({ret})" if n is not None else f"{ret}"
            return f"{owner}: its {what} {py.__name__} ({where}) returns {got}; a {what} returns {count}: {shape}"
        if count is not None and not all(isinstance(t, (numba.types.Number, numba.types.Boolean)) for t in ret):
            return (f"{owner}: its {what} {py.__name__} ({where}) returns {ret}; a {what} returns {count} "
                    f"numbers: {shape}")
        if count is None and not isinstance(ret, numba.types.NoneType):
            return f"{owner}: its {what} {py.__name__} ({where}) returns {ret}; a {what} returns {shape}"
    return None


def _where(func) -> str:
    filename, first = _rule_where(func)
    return f"{filename}:{first}"


def explain(cfg, seed: int, exc: Exception, sim=None, *, record_events: bool = False) -> Exception:
    """``exc``, raised by compiling the step kernel of ``cfg`` (``sim`` None) or by the compiled step of
    ``sim`` (a run with ``seed``), as a RuleRunError naming the rule, its file and line, and the step, or
    as a SimulationError naming the step; ``exc`` itself when nothing explains it.  Raise the result."""
    # imported on a failure only (explain runs when something already went wrong)
    from .errors import SimulationError
    from .state.flags import ErrorFlags

    try:
        if isinstance(exc, SimulationError) and sim is not None:  # an error bit the compiled step set
            why = _flagged(cfg, sim, ErrorFlags(int(sim.world.flags[0])))
            return RuleRunError(why) if why else exc
        if isinstance(exc, InfomarketError):
            return exc
        if sim is None:  # compiling (numba's typing error points into the generated kernel)
            why = explain_compile_failure(cfg, exc)
            if why:
                return RuleRunError(f"{why}; the step kernel cannot be compiled")
            return exc
        step = max(1, sim.clock)  # the loop counts a step before it calls any rule
        why = explain_run_failure(cfg, sim.seed, exc, step, record_events=record_events)
        if why:
            return RuleRunError(why)
        return SimulationError(f"step {step} (seed {sim.seed}) raised {type(exc).__name__}: {exc}; no rule of "
                               f"{', '.join(sim.kinds)} or {cfg.payment.scheme} raised it alone")
    except Exception:  # noqa: BLE001  (the explanation is best effort; the error itself is reported)
        return exc


def _flagged(cfg, sim, flags) -> str | None:
    """The rule behind an error bit of the step (``state.flags``), named with its file, or None."""
    from .state.flags import ErrorFlags  # imported on a failure only

    step = _first_flagged_step(cfg, sim)
    if ErrorFlags.BAD_WEIGHTS in flags:
        rule = get_payment(cfg.payment.scheme).weights
        return (f"payment scheme {cfg.payment.scheme!r}: its weight rule {rule.py_func.__name__} "
                f"({_where(rule.py_func)}) gave a negative or non-finite weight at step {step}; weights must be "
                f"finite and >= 0")
    if ErrorFlags.TX_OVERFLOW in flags:
        rules = [f"{k}: {get_behaviour(k).buy.py_func.__name__} ({_where(get_behaviour(k).buy.py_func)})"
                 for k in sim.kinds]
        return (f"a buy rule made more than 2 purchases per neighbour in one step (step {step}); the buy rules of "
                f"this run: {'; '.join(rules)}")
    return None


def _first_flagged_step(cfg, sim) -> int:
    """The step at which the run of ``sim`` first set an error bit: the compiled loop goes on to the end of
    its call before the host reads the bits, so the run is repeated one step at a time up to there."""
    try:
        again = Simulation(cfg, sim.seed, record_events=bool(sim.world.record))
    except Exception:  # noqa: BLE001 - a repeat that cannot start: the run's last step is the best known
        return sim.clock
    try:
        while again.clock < sim.clock:
            again.advance_to(again.clock + 1)
    except Exception:  # noqa: BLE001  (the repeat raised at the flagged step: its clock is that step)
        return again.clock
    return sim.clock
