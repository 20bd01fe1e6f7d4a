"""Benchmarks are measured, never asserted: these tests check what the benchmark *reports* (the
setups beside the floor, swarm sizes at the paper's density, sweep scaling), not how fast it is."""
import json
import math

import pytest

from infomarket.bench import floor_steps_per_second, run_bench, run_scaling
from infomarket.bench.swarm import scaled_config
from infomarket.cli import main


def test_the_floor_kernel_moves_every_robot_and_reports_its_rate():
    r = floor_steps_per_second(robots=60, steps=50, repeats=2)  # 60 robots: the grid path
    assert r["robots"] == 60 and r["steps"] == 50 and r["steps_per_second"] > 0
    assert r["robot_steps_per_second"] == pytest.approx(60 * r["steps_per_second"])


def test_each_setup_is_reported_beside_the_floor_measured_in_the_same_run():
    report = run_bench(["fig2A"], steps=200, repeats=2)
    setup, floor = report["setups"]["fig2A"], report["floor"]
    assert floor["robots"] == 25 and floor["steps"] == 200
    # the ratio is the floor's rate over the setup's: how many floors one step of the setup costs
    assert setup["ratio_to_floor"] == pytest.approx(floor["steps_per_second"] / setup["steps_per_second"])


def test_swarm_sizes_keep_the_papers_density_and_site_geometry():
    paper, big = scaled_config(25, 100), scaled_config(10000, 100)

    def area(c):
        return c.arena.width * c.arena.height

    assert area(big) / 10000 == pytest.approx(area(paper) / 25)  # 28 800 square units per robot
    k = math.sqrt(10000 / 25)  # 20
    assert (big.food.x, big.food.y, big.food.radius) == pytest.approx((200 * k, 300 * k, 50 * k))
    assert (big.nest.x, big.nest.y) == pytest.approx((1000 * k, 300 * k))
    assert [g.count for g in big.swarm.groups] == [10000] and big.swarm.groups[0].behaviour == "naive"


def test_bench_robots_prints_rate_and_peak_memory_per_size(capsys):
    assert main(["bench", "--robots", "25,60", "--steps", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    for n in ("25", "60"):
        r = report["robots"][n]
        assert r["robot_steps_per_second"] > 0 and r["steps"] == 50
        assert 20 < r["peak_rss_mb"] < 4000  # a Python process with numpy and numba loaded
    assert report["largest_vs_smallest"] == pytest.approx(
        report["robots"]["60"]["robot_steps_per_second"] / report["robots"]["25"]["robot_steps_per_second"])


@pytest.mark.parametrize("bad", ["", "10,x", "0", "-5"])
def test_bench_robots_refuses_what_is_not_a_list_of_counts(bad, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--robots", bad])
    assert exc.value.code == 2 and "robot counts" in capsys.readouterr().err


def test_scaling_runs_the_same_sweep_on_each_executor():
    pytest.importorskip("distributed")
    r = run_scaling(runs=2, steps=200)
    for k in ("local_1", "local_2", "dask_local_2"):
        assert r[k]["env_steps_per_second"] == pytest.approx(2 * 200 / r[k]["wall_seconds"])
    assert r["speedup_2_vs_1"] == pytest.approx(r["local_2"]["env_steps_per_second"]
                                                / r["local_1"]["env_steps_per_second"])


def test_the_floor_is_timed_once_a_round_before_that_rounds_setups(monkeypatch):
    """Interleaved, so a change in the machine's speed during the bench moves the floor and the setups
    alike: the order of the timed runs is floor, every setup, floor, every setup, ..."""
    from types import SimpleNamespace

    from infomarket.bench import setups

    order = []

    class FakeSimulation:  # records its timed runs; the kernel looks loaded from the disk cache
        def __init__(self, cfg, seed):
            self.name = cfg.name
            self._kernel = SimpleNamespace(step_all=SimpleNamespace(stats=SimpleNamespace(cache_hits={"x": 1})))
            self.run_seconds = 0.5

        def run(self):
            order.append(self.name)

    def floor_seconds(seed, steps):
        order.append(("floor", seed, steps))
        return 0.25

    monkeypatch.setattr(setups, "Simulation", FakeSimulation)
    monkeypatch.setattr(setups, "floor_seconds", floor_seconds)
    report = setups.run_bench(["fig2A", "fig4C"], steps=100, repeats=3)
    assert order == [("floor", 0, 1)] + [x for i in (1, 2, 3) for x in (("floor", i, 100), "fig2A", "fig4C")]
    assert report["floor"]["steps_per_second"] == 400 and report["floor"]["repeats"] == 3
    assert report["setups"]["fig2A"]["ratio_to_floor"] == 2  # 0.5 s a run against the floor's 0.25
