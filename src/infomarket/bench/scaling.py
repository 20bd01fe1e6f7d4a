"""Sweep throughput: the same runs on 1 and 2 local workers and on a local Dask cluster of 2."""
from __future__ import annotations

import time

from ..config import load_experiment


def run_scaling(experiment: str = "fig2A", runs: int = 32, steps: int = 15000) -> dict:
    """Steady-state sweep throughput (env-steps/s) with 1 and 2 local workers and a local Dask cluster
    of 2: each executor's workers are started and have the kernel loaded before the clock starts (the
    local pool's forked workers inherit it from the parent; Dask workers load it from the disk cache)."""
    import tempfile

    # the runner and store only when this bench runs (`infomarket bench` imports this module)
    from ..runner.execute import warm
    from ..runner.sweep import plan, run_sweep
    from ..store import Store

    cfg = load_experiment(experiment).with_overrides(steps=steps)
    conds = plan([cfg], runs=runs)
    out = {}
    setups = [("local_1", {"workers": 1}), ("local_2", {"workers": 2}), ("dask_local_2", None)]
    for name, kw in setups:
        with tempfile.TemporaryDirectory() as tmp:
            if kw is None:
                from distributed import Client, LocalCluster

                with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, Client(cluster) as client:
                    client.run(warm, cfg)  # workers up, kernel loaded, before the clock starts
                    t0 = time.perf_counter()
                    run_sweep(conds, Store(tmp), executor=client.get_executor(pure=False))
                    wall = time.perf_counter() - t0
            else:
                t0 = time.perf_counter()
                run_sweep(conds, Store(tmp), **kw)
                wall = time.perf_counter() - t0
        out[name] = {"env_steps_per_second": runs * steps / wall, "wall_seconds": wall}
    out["speedup_2_vs_1"] = out["local_2"]["env_steps_per_second"] / out["local_1"]["env_steps_per_second"]
    out["dask_vs_local_2"] = out["dask_local_2"]["env_steps_per_second"] / out["local_2"]["env_steps_per_second"]
    return {"experiment": experiment, "runs": runs, "steps": steps, **out}
