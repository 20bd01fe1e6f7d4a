"""Playing policies of the adaptive attacker: many (policy, run seed) episodes through the RL interface's
compiled runs (``agents.runs.Runs``, the engine under ``AttackVectorEnv``), in batches, inline or on a local
process pool.

One episode is one run of the configuration with run seed s (the seed ``simulate`` takes): every
``interval`` steps the agents observe (``agents.observe.OBSERVATION``), the policy sets their action
parameters, and the engine runs ``interval`` steps, exactly as ``AttackVectorEnv.step`` does.  The runs are
reset with the given run seeds directly: the vector env's ``reset`` draws each episode's run seed from its
own seed, and the confirmation needs runs on the driver's seeds.  Each run depends only on its seed and
its policy, so the batching and the number of workers never change a result.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .. import interrupts
from ..config import sizes
from ..errors import UsageError
from ..agents.runs import Runs
from ..runner.execute import local_executor
from .objective import per_run

#: Runs stepped together in one compiled call (their worlds are alive at once).
BATCH = 32

_runs: dict[tuple, Runs] = {}  # per process: built once per (configuration, actions, batch size)


def _runs_for(cfg, size: int, actions: tuple[str, ...]) -> Runs:
    key = (cfg.model_dump_json(), actions)
    if any(k[:2] != key for k in _runs):
        _runs.clear()  # one configuration at a time (worlds are large); ``chunks`` makes at most two sizes
    if key + (size,) not in _runs:
        _runs[key + (size,)] = Runs(cfg, size, actions=actions)
    return _runs[key + (size,)]


def check_memory(cfg, batch: int, what: str, episodes: int = 0, weights: int = 0) -> None:
    """Refuse, before any world is built, a batch whose worlds would not fit in memory, with a policy of
    ``weights`` numbers for each of ``episodes`` episodes (a generation's candidates, each run's copy)."""
    too_big = sizes.batch_too_big(cfg, batch, what, extra={"policies per episode": 8 * episodes * weights})
    if too_big:
        raise UsageError(too_big)


def act(weights: np.ndarray, obs: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Each run's agents' actions: ``weights`` [B, O + 1, k] (rows: one per observation column, then the
    constant), ``obs`` [B, agents, O] -> [B, agents, k], ``low + (high - low) * clip(obs . W + b, 0, 1)``."""
    u = np.einsum("bao,bok->bak", obs.astype(np.float64), weights[:, :-1]) + weights[:, None, -1]
    return low + (high - low) * np.clip(u, 0.0, 1.0)


def _episodes(runs: Runs, weights: np.ndarray, seeds, interval: int) -> None:
    """Play one episode per run of ``runs``: run b with seed ``seeds[b]`` under policy ``weights[b]``."""
    runs.reset(np.arange(runs.size), [int(s) for s in seeds])
    while True:
        clocks = runs.clocks
        if clocks.min() >= runs.steps:
            return
        runs.act(act(weights, runs.obs, runs.low, runs.high))
        runs.advance(clocks + interval)


def _values(runs: Runs) -> tuple[np.ndarray, np.ndarray]:
    """Per run: honest items per honest robot and the Byzantine robots' summed wealth share, as the
    search's objectives define them (``objective.per_run``), read from the finished worlds."""
    items = runs.items / max(len(runs.honest), 1)
    liar = np.zeros(runs.size)
    for b, w in enumerate(runs.worlds):
        total = float(w.balance.sum())
        if total > 0:
            mask = np.ones(len(w.balance), bool)
            mask[runs.honest] = False
            liar[b] = float(w.balance[mask].sum()) / total
    return items, liar


def play_chunk(cfg, actions: tuple[str, ...], interval: int, weights: np.ndarray, seeds, robots: bool = False):
    """Play ``len(seeds)`` episodes in one batch; returns (items, liar_wealth) per episode, or with
    ``robots`` the per-run values of ``objective.per_run`` computed from each run's robots table (the
    table ``simulate`` returns), as a frame with columns run (0..), items, liar_wealth."""
    runs = _runs_for(cfg, len(seeds), actions)
    _episodes(runs, weights, seeds, interval)
    if not robots:
        return _values(runs)
    frames = []
    for b, sim in enumerate(runs.sims.sims):
        r = sim.result().robots
        frames.append(r.assign(experiment=cfg.name, condition="adaptive", run=b))
    per = per_run(pd.concat(frames, ignore_index=True))
    return per[["run", "items", "liar_wealth"]].reset_index(drop=True)


def chunks(n: int, batch: int) -> list[slice]:
    """``n`` episodes in batches of at most ``batch``, as even as possible (at most two batch sizes)."""
    k = -(-n // batch)
    edges = np.linspace(0, n, k + 1).round().astype(int)
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


class Player:
    """Plays (policy, seed) episodes of one configuration, inline (``workers`` = 1) or on a local process
    pool held for the player's life (``with Player(...) as p``)."""

    def __init__(self, cfg, actions: tuple[str, ...], interval: int, *, batch: int = BATCH, workers: int = 1):
        self.cfg, self.actions, self.interval = cfg, tuple(actions), int(interval)
        self.batch, self.workers = int(batch), int(workers)
        self._pool = None

    def __enter__(self) -> Player:
        if self.workers > 1:  # load the kernels here: forked workers inherit them instead of each loading them
            _runs_for(self.cfg, 1, self.actions)
        self._executor = local_executor(self.workers)
        self._pool = self._executor.__enter__()
        return self

    def __exit__(self, *exc) -> bool:
        self._pool = None
        return bool(self._executor.__exit__(*exc))

    def play(self, weights: np.ndarray, seeds, on_done=None) -> tuple[np.ndarray, np.ndarray]:
        """(items, liar_wealth) of episode i: policy ``weights[i]`` on run seed ``seeds[i]``."""
        n = len(seeds)
        items, liar = np.zeros(n), np.zeros(n)
        parts = chunks(n, min(self.batch, -(-n // max(self.workers, 1))))
        if self._pool is None or self.workers <= 1:
            for s in parts:
                items[s], liar[s] = play_chunk(self.cfg, self.actions, self.interval, weights[s], seeds[s])
                interrupts.check()
                if on_done:
                    on_done(s.stop - s.start)
            return items, liar
        futures = [(s, self._pool.submit(play_chunk, self.cfg, self.actions, self.interval, weights[s], seeds[s]))
                   for s in parts]
        for s, f in futures:  # the wait is interrupted by a signal at once; the pool is then stopped
            items[s], liar[s] = f.result()
            interrupts.check()
            if on_done:
                on_done(s.stop - s.start)
        return items, liar

    def per_run(self, weights: np.ndarray, seeds) -> pd.DataFrame:
        """``objective.per_run``'s items and liar_wealth of episode i (column ``run`` = i), from each
        finished run's robots table."""
        parts = chunks(len(seeds), min(self.batch, -(-len(seeds) // max(self.workers, 1))))
        args = [(self.cfg, self.actions, self.interval, weights[s], seeds[s], True) for s in parts]
        if self._pool is None or self.workers <= 1:
            frames = []
            for a in args:
                frames.append(play_chunk(*a))
                interrupts.check()
        else:
            frames = [f.result() for f in [self._pool.submit(play_chunk, *a) for a in args]]
        for s, f in zip(parts, frames):
            f["run"] += s.start
        return pd.concat(frames, ignore_index=True)
