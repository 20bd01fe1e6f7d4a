"""``infomarket ros swarm`` end to end: real agent processes over ROS 2, a real Hardhat node, one agent
process per robot, each agent doing what the engine's behaviours decided (tests/ros/common.py says
what the runs hold). Skipped when the ROS 2 wheels are missing.
"""
from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

import pytest
from eth_account import Account

from ..procs import HANG
from .common import (ROBOTS, answers, check_ledger, engine_ledger, needs_ros, own_domain, start_controller,
                     swarm)

pytestmark = needs_ros
STEPS = 1000


@pytest.fixture(scope="module")
def engine():
    return engine_ledger(STEPS)


def test_agents_in_lock_step_reach_the_engines_ledger(procs, tmp_path, rpc, engine):
    """Robots 0 and 1 share one agent process and ask a controller (examples/ros_controller.py, a plain
    rclpy process) before buying or selling; robot 2, the seller, has a process of its own and does what
    its tasks say. The controller agrees with the behaviour, so the ledger is the engine's; each sale
    was put to the buyer's controller (the faults test below runs one process per robot, no controller)."""
    log, domain = tmp_path / "answers.jsonl", own_domain()
    start_controller(procs, domain, log, "0-1")
    report = swarm(procs, tmp_path / "run", rpc, STEPS, "--agents-per-process", "2", "--controlled", "0,1",
                   domain=domain)
    check_ledger(report, engine)
    assert report["processes"] == 2 and report["robots_per_process"] == 2 and report["restarted_agents"] == 0
    assert report["controlled"] == [0, 1] and report["declined"] == 0
    agents = tmp_path / "run" / "agents"
    assert sorted(p.name for p in agents.glob("*.log")) == ["robot_2.log", "robots_0-1.log"]
    assert report["messages"]["offer"] >= engine["sales"] and report["messages"]["acceptance"] >= engine["sales"]
    assert report["gas"]["reveal_mean"] > 0 and report["gas"]["deposit_mean"] > 0
    keys = [agents / f"robot_{i}" / "key" for i in range(ROBOTS)]
    assert all(k.stat().st_mode & 0o777 == 0o600 for k in keys)
    assert len({k.read_text() for k in keys}) == ROBOTS  # each robot its own key, two of them in one process
    got = answers(log)
    # each sale put to its buyer's controller, naming the seller; the seller (robot 2) asked nobody
    assert {(a["step"], a["seller"], a["robot"]) for a in got if a["question"] == "buy"} == set(engine["sale_list"])
    assert all(a["yes"] for a in got) and not any(a["question"] == "sell" for a in got)


def test_killed_agent_dropped_messages_and_hostile_ones_lose_nothing(procs, tmp_path, rpc, engine):
    """SIGKILL robot 2 (the seller, in a process of its own) in the middle of a sale, lose a fifth of every
    agent's messages, and send malformed, forged and replayed messages before every sale: the ledger is
    still the engine's, each sale revealed once, the restarted agent kept its key, and every hostile
    message was refused and logged. (Robots 0 and 1 share a process: one agent start-up less.)"""
    key = tmp_path / "agents" / "robot_2" / "key"
    report = swarm(procs, tmp_path, rpc, STEPS, "--fault", "kill:2@555", "--fault", "drop:0.2", "--fault", "hostile",
                   "--retry-after", "0.3", "--agents-per-process", "2")
    check_ledger(report, engine)
    assert report["restarted_agents"] == 1 and report["processes"] == 2
    assert "robot 2's agent killed (SIGKILL) in the middle of a sale" in report["stdout"]
    assert report["balances"][2]["address"] == Account.from_key(bytes.fromhex(key.read_text())).address
    assert report["messages"]["retries"] > 0  # the drops were made up for by sending again
    assert report["refused_messages"] > 0  # notices on /market/done (themselves subject to the drops)
    logs = "".join(p.read_text() for p in (tmp_path / "agents").glob("*.log"))
    refused = [line for line in logs.splitlines() if ": refused " in line]
    assert len(refused) >= engine["sales"]  # three hostile messages are sent before each sale
    assert any("refused offer: malformed" in line for line in refused)
    assert any("refused offer" in line and "signed by" in line for line in refused)  # forged
    assert any("refused acceptance" in line and "replayed" in line for line in refused)
    assert key.stat().st_mode & 0o777 == 0o600


def _command(pid: int) -> str:
    try:
        return (Path("/proc") / str(pid) / "cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:  # gone meanwhile
        return ""


def test_ctrl_c_ends_every_process_of_the_swarm(procs, tmp_path):
    """Ctrl-C once the chain node and the agents (a process per robot by default) have started: the swarm
    ends, and no agent or chain node of its session is left (the swarm starts its own node here)."""
    proc = procs.cli("ros", "swarm", "fig4C", "--robots", "2", "--steps", "100000", "--out", tmp_path,
                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while True:
        commands = [_command(p) for p in procs.leftovers(proc)]
        if sum(" ros agent " in c for c in commands) == 2 and any("hardhat" in c for c in commands):
            break
        assert proc.poll() is None, "the swarm ended before its agents started"
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=HANG)
    assert proc.returncode != 0
    assert procs.leftovers(proc) == []
