"""Many runs against the engine's own rate: a sweep and a reduced attack search, each into a results store
of its own, beside the engine stepping the same configuration alone, in this process.

Every rate here is env-steps per second of this process's CPU time (``time.process_time``), not of wall
time: the machine may be shared, and CPU time charges each part only for what it did itself.  Everything
runs in this process (the inline executor), so the CPU time counts the whole path of a run: planning,
world building, stepping, results, store writes and checksums, and (the search) reading the store back
between generations.  Kernels are loaded and the optimiser's libraries imported before any clock starts.

- engine: ``Simulation.run`` alone, world building excluded: the same ``repeats`` runs before the first
  path and after each one; a path's ratio is against the median of the engine's runs just before and just
  after it (the machine's speed may drift over a bench of minutes), ``engine`` reports all of them;
- sweep: ``run_sweep`` of ``runs`` runs of the same configuration into a fresh store;
- search: ``search.driver.search_cell`` of one cell (the start runs of every baseline, the CMA-ES and
  random-search generations, the race, the confirmation), reduced to ``budget`` evaluations of
  ``popsize``, one restart, the coarsest rotation grid; and again on a pool of ``workers`` processes
  (``search_pool``), where the CPU time is the parent's and the workers' together, and the wall time
  shows what CPU time cannot: workers idle while the parent writes, reads the store between generations
  and asks CMA-ES for the next points.

Each path reports runs per second beside env-steps per second (the same runs: every run has ``steps``
steps), and each ratio is the rate over the engine's, whose runs per second are those of ``Simulation.run``.
"""
from __future__ import annotations

import resource
import statistics
import tempfile
import time
from pathlib import Path

from ..config import load_experiment
from ..engine.simulation import Simulation
from ..runner.execute import local_executor, warm
from ..runner.plan import BASE, Condition
from ..runner.sweep import run_sweep
from ..search import study as study_mod
from ..search.driver import search_cell, store_runner
from ..seeds import run_seed
from ..store import Store

#: The setup: the attack search's cell it reports first (outlier penalisation with staking, 3 of 25
#: robots running the parameterised attacker), whose runs the study made by the ten thousand.
SETUP = "attack_search"
CELL = ("staking", 3)
#: The goals of the many-run paths, as fractions of the engine's rate (docs/performance.md).
GOALS = {"sweep": 0.8, "search": 0.8}


def engine_seconds(cfg, repeats: int) -> list[float]:
    """CPU seconds of ``Simulation.run`` alone (world building excluded) for the runs of seeds 0 to
    ``repeats`` - 1: the same runs every time it is called, so two calls differ by the machine alone."""
    seconds = []
    for i in range(repeats):
        sim = Simulation(cfg, run_seed(cfg.seed, i))
        t0 = time.process_time()
        sim.run()
        seconds.append(time.process_time() - t0)
    return seconds


def engine_rate(cfg, seconds: list[float]) -> dict:
    """The engine's rates from its runs' CPU seconds (the median run)."""
    med = statistics.median(seconds)
    return {"env_steps_per_second": cfg.steps / med, "runs_per_second": 1.0 / med, "cpu_seconds_per_run": med,
            "repeats": len(seconds)}


def sweep_rate(cfg, runs: int, folder: Path) -> dict:
    """Sweep ``runs`` runs of ``cfg`` into a fresh store under ``folder`` and return runs, env-steps and CPU
    seconds: the throughput of the whole path, store included."""
    cond = Condition(cfg.name, BASE, {}, cfg, runs, cfg.seed, 0)
    store = Store(folder / "sweep")
    t0 = time.process_time()
    report = run_sweep([cond], store)
    cpu = time.process_time() - t0
    return {"runs": report.done, "env_steps": report.env_steps, "cpu_seconds": cpu,
            "env_steps_per_second": report.env_steps / cpu, "runs_per_second": report.done / cpu}


def search_rate(steps: int, transitory: int, folder: Path, *, budget: int, popsize: int, runs: int,
                workers: int = 1) -> dict:
    """The reduced search, inline (CPU time of this process), or on a local pool of ``workers`` processes
    as ``infomarket attack-search`` runs it (one pool for the whole search): then the wall time, and the
    CPU time of this process and its workers together (``cpu_seconds``)."""
    import cma  # noqa: F401 - imported before the clock starts (a fixed cost, not a run's)

    st = study_mod.load(load_experiment(SETUP), budget=budget, popsize=popsize, runs=runs, restarts=1, finalists=1,
                        race=[max(runs, 2)], confirmation_runs=max(runs, 2), grid_step=180.0)
    cell = study_mod.cells(st, [CELL[0]], [CELL[1]])[0]
    store = Store(folder / f"search{workers}", cache=True)
    t0, w0, c0 = time.process_time(), time.perf_counter(), _children_cpu()
    if workers > 1:
        warm(cell.with_attack({}, steps=steps, transitory=transitory))  # as the command does: workers inherit it
        with local_executor(workers) as pool:
            result = search_cell(st, cell, store, run=store_runner(store, executor=pool), steps=steps,
                                 transitory=transitory)
    else:
        result = search_cell(st, cell, store, run=store_runner(store), steps=steps, transitory=transitory)
    cpu = time.process_time() - t0 + _children_cpu() - c0
    wall = time.perf_counter() - w0
    env_steps = int(store.runs().steps.sum())
    out = {"runs": result.done, "env_steps": env_steps, "cpu_seconds": cpu, "env_steps_per_second": env_steps / cpu,
           "runs_per_second": result.done / cpu, "budget": budget, "popsize": popsize, "runs_per_candidate": runs,
           "workers": workers, "phases": {k: v["runs"] for k, v in result.cost.items()}}
    if workers > 1:
        out.update(wall_seconds=wall, wall_env_steps_per_second=env_steps / wall,
                   wall_runs_per_second=result.done / wall)
    return out


def _children_cpu() -> float:
    """CPU seconds of this process's finished child processes (a pool's workers, once shut down)."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_many_bench(*, steps: int = 30000, repeats: int = 5, sweep_runs: int = 32, budget: int = 8,
                   popsize: int = 4, runs: int = 4, workers: int = 2) -> dict:
    """The engine, a sweep and a reduced attack search on the ``SETUP`` cell, ``steps`` steps a run (the
    last third counted); rates per CPU second and their ratios to the engine's.  With ``workers`` > 1,
    the search again on a local pool (``search_pool``), whose wall-time rate only a quiet machine makes
    meaningful (``wall_ratio_to_engine_per_worker``)."""
    transitory = steps - max(1, steps // 3)
    st = study_mod.load(load_experiment(SETUP))
    cfg = study_mod.cells(st, [CELL[0]], [CELL[1]])[0].with_attack({}, steps=steps, transitory=transitory)
    out = {"setup": f"{SETUP} [defence={CELL[0]}, byzantines={CELL[1]}]", "steps": steps,
           "clock": "process CPU time"}
    Simulation(cfg, 0)  # load the kernel
    brackets = [engine_seconds(cfg, repeats)]  # the engine before the first path and after each one
    paths = ["sweep", "search"] + (["search_pool"] if workers > 1 else [])
    with tempfile.TemporaryDirectory(prefix="infomarket-bench-") as tmp:
        search_rate(min(steps, 50), 10, Path(tmp) / "warm", budget=2, popsize=2, runs=1)  # loads what a search loads
        for k in paths:
            if k == "sweep":
                out[k] = sweep_rate(cfg, sweep_runs, Path(tmp))
            else:
                out[k] = search_rate(steps, transitory, Path(tmp), budget=budget, popsize=popsize, runs=runs,
                                     workers=workers if k == "search_pool" else 1)
            brackets.append(engine_seconds(cfg, repeats))
    out["engine"] = engine_rate(cfg, [s for b in brackets for s in b])
    for j, k in enumerate(paths):
        # against the engine's runs just before and just after it: the machine's speed may drift during a
        # bench of minutes, and a path's ratio should not carry what it did in another path's minute
        e = engine_rate(cfg, brackets[j] + brackets[j + 1])
        out[k].update(ratio_to_engine=out[k]["env_steps_per_second"] / e["env_steps_per_second"],
                      engine_env_steps_per_second=e["env_steps_per_second"],
                      engine_runs_per_second=e["runs_per_second"],
                      goal=GOALS["search" if k == "search_pool" else k])
    if "search_pool" in out:  # wall time on a quiet machine: against the engine on every worker at once
        p = out["search_pool"]
        p["wall_ratio_to_engine_per_worker"] = (p["wall_env_steps_per_second"]
                                                / (workers * p["engine_env_steps_per_second"]))
    return out
