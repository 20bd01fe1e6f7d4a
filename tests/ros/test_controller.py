"""A robot's own controller deciding its agent's sales, and many agents hosted in one process.

The controller is examples/ros_controller.py, a plain rclpy process that imports nothing of
infomarket, as a robot's own code would be: it answers the agents' questions on
``/robot_N/market/ask`` on ``/robot_N/market/decision`` and logs each question with its answer. Both
runs host the three robots' agents in one OS process (``--agents-per-process 3``), the cheap way to
start them. Skipped when the ROS 2 wheels are missing.
"""
from __future__ import annotations

import json
import sys

from .common import EXAMPLE_CONTROLLER, ROBOTS, check_ledger, engine_ledger, needs_ros, own_domain, ros_env, swarm

pytestmark = needs_ros
HOSTED = ("--agents-per-process", str(ROBOTS), "--controlled", "all")


def start_controller(procs, domain: int, log, *rule: str):
    return procs.start([sys.executable, EXAMPLE_CONTROLLER, "--robots", f"0-{ROBOTS - 1}", "--log", log, *rule],
                       env=ros_env(domain))


def answers(log) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []


def test_a_controller_that_agrees_with_the_behaviour_keeps_the_engines_ledger(procs, tmp_path, rpc):
    """Every robot's agent asks the controller before it sells and before it buys; the controller says
    yes, so the ledger is the engine's. The three agents share one process."""
    expected, log, domain = engine_ledger(1000), tmp_path / "answers.jsonl", own_domain()
    start_controller(procs, domain, log)
    report = swarm(procs, tmp_path / "run", rpc, 1000, *HOSTED, domain=domain)
    check_ledger(report, expected)
    assert report["processes"] == 1 and report["robots_per_process"] == ROBOTS and report["declined"] == 0
    assert sorted(p.name for p in (tmp_path / "run" / "agents").glob("*.log")) == ["robots_0-2.log"]
    keys = {(tmp_path / "run" / "agents" / f"robot_{i}" / "key").read_text() for i in range(ROBOTS)}
    assert len(keys) == ROBOTS  # one process, still a key per robot
    got = answers(log)
    # each sale asked of its seller ("sell", naming the buyer) and of its buyer ("buy", naming the seller)
    sells = {(a["step"], a["robot"], a["buyer"]) for a in got if a["question"] == "sell"}
    buys = {(a["step"], a["seller"], a["robot"]) for a in got if a["question"] == "buy"}
    assert sells == buys == set(expected["sale_list"])
    assert all(a["yes"] for a in got)


def test_a_controller_that_declines_to_buy_stops_every_sale(procs, tmp_path, rpc):
    """The controller refuses every purchase: the sellers still offered (their controller said yes to
    selling), no acceptance is signed, nothing reaches the chain, every robot keeps its initial wealth,
    and the report names each sale the engine made and the controller declined (exit status 1)."""
    expected, log, domain = engine_ledger(750), tmp_path / "answers.jsonl", own_domain(50)
    assert expected["sales"] > 0 and expected["deposits"] == 0
    start_controller(procs, domain, log, "--refuse", "buy")
    report = swarm(procs, tmp_path / "run", rpc, 750, *HOSTED, domain=domain, status=1)
    assert report["on_chain_matches_engine"] is False
    assert report["light_contracts"] == 0 and report["declined"] == expected["sales"]
    assert len(report["disagreements"]) == expected["sales"]
    assert all("buyer's controller declined" in d for d in report["disagreements"])
    assert report["messages"]["offer"] >= expected["sales"] and report["messages"]["acceptance"] == 0
    assert [row["on_chain"] for row in report["balances"]] == [expected["initial_wealth"]] * ROBOTS
    got = answers(log)
    assert {(a["step"], a["seller"], a["robot"]) for a in got if a["question"] == "buy"} == set(expected["sale_list"])
    assert not any(a["yes"] for a in got if a["question"] == "buy")
