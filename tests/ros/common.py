"""What the ROS 2 swarm tests share: the engine's own ledger of a run, the swarm run, the ledger check.

The expected ledger comes from ``simulate`` run here (the engine alone, no agent, no chain), and the
rounding bound from its events (a unit per share paid at each deposit, either side), so the swarm's own
comparison is checked against an independent one. The runs are small: 3 robots of fig4C with seed 18,
where robot 2 sells to robot 1 15 times in steps 548-562 and robot 2 deposits at step 917 (1000 steps);
with 750 steps the same 15 sales happen and no deposit.
"""
from __future__ import annotations

import functools
import json
import os
import sys
from pathlib import Path

import pytest

from infomarket.ros import env

REASON = env.missing()
needs_ros = pytest.mark.skipif(REASON is not None, reason=f"the ROS 2 wheels cannot be loaded: {REASON}")
ROBOTS, SEED = 3, 18
EXAMPLE_CONTROLLER = Path(__file__).resolve().parents[2] / "examples" / "ros_controller.py"


def run_args(steps: int) -> tuple[str, ...]:
    return ("fig4C", "--robots", str(ROBOTS), "--steps", str(steps), "--seed", str(SEED))


@functools.cache
def engine_ledger(steps: int) -> dict:
    """The engine's own run of the swarm: final wealth, the trades, the rounding bound, initial wealth."""
    from infomarket import load_experiment, simulate
    from infomarket.evm.cli import demo_config

    config = demo_config(load_experiment("fig4C"), ROBOTS, steps, "staking")
    result = simulate(config, seed=SEED, record_events=True)
    bound, open_sellers = [0] * ROBOTS, [[] for _ in range(ROBOTS)]
    sales = []
    for ev in result.events.itertuples():
        if ev.kind == "purchase":
            open_sellers[ev.buyer].append(ev.seller)
            sales.append((int(ev.step), int(ev.seller), int(ev.buyer)))
        elif ev.kind == "deposit":
            bound[ev.buyer] += len(open_sellers[ev.buyer])
            for s in open_sellers[ev.buyer]:
                bound[s] += 1
            open_sellers[ev.buyer] = []
    kinds = result.events["kind"].value_counts()
    return {"wealth": result.robots.sort_values("robot")["wealth"].tolist(), "bound": bound, "sale_list": sales,
            "sales": int(kinds.get("purchase", 0)), "deposits": int(kinds.get("deposit", 0)),
            "open": [len(s) for s in open_sellers], "initial_wealth": float(config.payment.initial_wealth)}


def ros_env(domain: int) -> dict:
    """The environment of a process in ROS domain ``domain`` (the wheels' libraries found)."""
    return env.child_env({"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"})


def own_domain(offset: int = 0) -> int:
    """A ROS domain for one test (101-200: never one a swarm picks for itself, 1-100)."""
    return 101 + (os.getpid() + offset) % 100


def swarm(procs, out: Path, rpc: str, steps: int, *extra: str, domain: int | None = None, status: int = 0):
    """Run ``infomarket ros swarm`` to its end; its report, with its output under ``stdout``."""
    done = procs.run([sys.executable, "-m", "infomarket.cli", "ros", "swarm", *run_args(steps), "--out", out,
                      "--rpc", rpc, *extra], env=ros_env(domain) if domain else None)
    assert done.returncode == status, done.stderr[-3000:] + done.stdout[-2000:]
    report = json.loads((out / "report.json").read_text())
    report["stdout"] = done.stdout
    return report


def check_ledger(report: dict, engine: dict) -> None:
    assert engine["sales"] > 0 and engine["deposits"] > 0  # the comparison proves something
    assert report["on_chain_matches_engine"] is True
    assert report["light_contracts"] == engine["sales"] and report["deposits"] == engine["deposits"]
    for row, wealth, bound, n_open in zip(report["balances"], engine["wealth"], engine["bound"], engine["open"]):
        assert row["engine"] == pytest.approx(wealth, abs=1e-12)
        assert abs(row["on_chain"] * 1e9 - wealth * 1e9) <= bound + 0.5, row
        assert row["open_purchases"] == {"on_chain": n_open, "engine": n_open, "same_sellers": True}, row


def start_controller(procs, domain: int, log: Path, robots: str, *rule: str):
    """examples/ros_controller.py for ``robots`` in ROS domain ``domain``, logging to ``log``."""
    return procs.start([sys.executable, EXAMPLE_CONTROLLER, "--robots", robots, "--log", log, *rule],
                       env=ros_env(domain))


def answers(log: Path) -> list[dict]:
    """The controller's log: each question it was asked, with its answer."""
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []
