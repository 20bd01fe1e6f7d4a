"""The RL interface's throughput (``infomarket bench --env``): the vector environment
(``rl.AttackVectorEnv``, B runs stepped K engine steps per ``step`` in one compiled call) against the
engine alone (``Simulation``, stepping only) on the same runs, in the same process.

Rates, each a median over ``repeats``, per second of this process's CPU time (``time.process_time``: the
machine may be shared, and CPU time charges each side only for what it did):

- engine env-steps/s: the episode's own B runs (its seeds), each stepped alone by ``Simulation`` (world
  building and result tables excluded), B x ``steps`` over their CPU time: the engine's rate for the
  same runs, so the ratio compares like with like and does not hang on one short run's timing;
- vector env-steps/s: B x ``steps`` over the CPU time of ``reset(seed=...)`` plus the ``steps / K`` calls
  of ``step`` of one episode, through the Gymnasium API (worlds built, actions written, observations and
  rewards computed: everything an RL loop pays, except the policy);
- agent-steps/s: agent decisions per second, vector env-steps/s x agents / K;
- ratio: vector env-steps/s over engine env-steps/s (goal ``GOAL`` at B = 64, K = 10).
"""
from __future__ import annotations

import statistics
import time

import numpy as np

from .._version import __version__
from ..engine.simulation import Simulation
from ..seeds import run_seed

#: The setup: the attack search's base cell (22 sceptics, 3 `attacker` robots, outlier penalisation with
#: staking), whose attackers are the environments' agents.
ENV_SETUP = "attack_search"
GOAL = 0.9


def run_env_bench(*, steps: int = 3000, batch: int = 64, interval: int = 10, repeats: int = 5,
                  setup: str = ENV_SETUP) -> dict:
    """Time the reinforcement-learning environment: ``batch`` swarms of ``setup`` stepped ``interval`` steps per
    action.

    Returns:
        Rates of the vector environment and of the engine alone on the same runs (medians of ``repeats``,
        process CPU time) and their ratio, as a dict for the bench's JSON output.
    """
    from ..rl.envs import AttackVectorEnv, configured  # the optional rl extra: only when this bench runs

    cfg = configured(setup, None, steps, min(1000, steps // 3))
    t0 = time.perf_counter()
    env = AttackVectorEnv(cfg, batch, interval=interval)
    compile_seconds = time.perf_counter() - t0
    Simulation(cfg, run_seed(cfg.seed, 0))  # the kernel is loaded already; this warms the view module too
    action = np.tile(env.runs.default_action, (batch, 1, 1)).astype(np.float32)  # the constant 20° liar
    calls = -(-steps // interval)
    engine, vector = [], []
    for i in range(repeats):  # the two interleaved, so a busy machine slows both alike
        t = time.process_time()
        _, info = env.reset(seed=run_seed(cfg.seed, i))
        for _ in range(calls):
            env.step(action)
        vector.append(time.process_time() - t)
        engine.append(_engine_seconds(cfg, info["seed"]))
    e_rate = batch * steps / statistics.median(engine)
    v_wall = statistics.median(vector)
    v_rate = batch * steps / v_wall
    agents = len(env.runs.agents)
    return {"version": __version__, "setup": setup, "robots": cfg.swarm.robots, "agents": agents,
            "batch": batch, "interval": interval, "steps": steps, "repeats": repeats,
            "engine_env_steps_per_second": e_rate,
            "vector_env_steps_per_second": v_rate,
            "agent_steps_per_second": v_rate * agents / interval,
            "vector_calls_per_second": calls / v_wall,
            "ratio_to_engine": v_rate / e_rate, "goal": GOAL,
            "vector_seconds_per_episode": v_wall, "engine_seconds_per_run": statistics.median(engine) / batch,
            "compile_seconds": compile_seconds, "clock": "process CPU time"}


def _engine_seconds(cfg, seeds) -> float:
    """CPU seconds of stepping the runs of ``seeds`` to their end, one after the other (each world built
    before its clock starts, and no result tables made after it): the vector episode's runs, which the
    constant default action leaves as the configuration makes them (tests/rl/test_runs.py)."""
    total = 0.0
    for seed in seeds:
        sim = Simulation(cfg, int(seed))
        t = time.process_time()
        sim.advance_to(cfg.steps)  # the steps alone: the vector env makes no result tables
        total += time.process_time() - t
    return total
