"""A robot's own controller overruling the registered behaviour (test_swarm.py has one agreeing with it).

The controller is examples/ros_controller.py, a plain rclpy process that imports nothing of
infomarket, as a robot's own code would be: it answers the agents' questions on
``/robot_N/market/ask`` on ``/robot_N/market/decision`` and logs each question with its answer. The run
hosts the three robots' agents in one OS process (``--agents-per-process 3``), the cheap way to start
them. Skipped when the ROS 2 wheels are missing.
"""
from __future__ import annotations

from .common import ROBOTS, answers, engine_ledger, needs_ros, own_domain, start_controller, swarm

pytestmark = needs_ros
HOSTED = ("--agents-per-process", str(ROBOTS), "--controlled", "all")


def test_a_controller_that_declines_to_buy_stops_every_sale(procs, tmp_path, rpc):
    """The controller refuses every purchase: the sellers still offered (their controller said yes to
    selling), no acceptance is signed, nothing reaches the chain, every robot keeps its initial wealth,
    and the report names each sale the engine made and the controller declined (exit status 1)."""
    expected, log, domain = engine_ledger(750), tmp_path / "answers.jsonl", own_domain(50)
    assert expected["sales"] > 0 and expected["deposits"] == 0
    start_controller(procs, domain, log, f"0-{ROBOTS - 1}", "--refuse", "buy")
    report = swarm(procs, tmp_path / "run", rpc, 750, *HOSTED, domain=domain, status=1)
    assert report["on_chain_matches_engine"] is False
    assert report["light_contracts"] == 0 and report["declined"] == expected["sales"]
    assert len(report["disagreements"]) == expected["sales"]
    assert all("buyer's controller declined" in d for d in report["disagreements"])
    assert report["messages"]["offer"] >= expected["sales"] and report["messages"]["acceptance"] == 0
    assert [row["on_chain"] for row in report["balances"]] == [expected["initial_wealth"]] * ROBOTS
    got = answers(log)
    assert {(a["step"], a["seller"], a["robot"]) for a in got if a["question"] == "buy"} == set(expected["sale_list"])
    assert {(a["step"], a["robot"], a["buyer"]) for a in got if a["question"] == "sell"} == set(expected["sale_list"])
    assert all(a["yes"] == (a["question"] == "sell") for a in got)
