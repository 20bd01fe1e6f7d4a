"""``infomarket ros swarm`` end to end: real agent processes over ROS 2, a real Hardhat node.

The expected ledger comes from ``simulate`` run here (the engine alone, no agent, no chain), and the
rounding bound from its events (a unit per share paid at each deposit, either side), so the swarm's own
comparison is checked against an independent one. The runs are small (3 robots, 1000 steps, seed 18:
15 sales of robot 2 to robot 1 in steps 548-562, then robot 2's deposit at step 917) and share one
node. Skipped when the ROS 2 wheels are missing.
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from eth_account import Account

from infomarket.ros import env

from ..evm.node import running_node
from ..procs import HANG

REASON = env.missing()
pytestmark = pytest.mark.skipif(REASON is not None, reason=f"the ROS 2 wheels cannot be loaded: {REASON}")
ROBOTS, STEPS, SEED = 3, 1000, 18
RUN = ("fig4C", "--robots", str(ROBOTS), "--steps", str(STEPS), "--seed", str(SEED))


@pytest.fixture(scope="module")
def rpc():
    with running_node() as url:
        yield url


@pytest.fixture(scope="module")
def engine():
    """The engine's own run of the same swarm: final wealth, sales, deposits, the rounding bound."""
    from infomarket import load_experiment, simulate
    from infomarket.evm.cli import demo_config

    result = simulate(demo_config(load_experiment("fig4C"), ROBOTS, STEPS, "staking"), seed=SEED, record_events=True)
    bound, open_sellers = [0] * ROBOTS, [[] for _ in range(ROBOTS)]
    for ev in result.events.itertuples():
        if ev.kind == "purchase":
            open_sellers[ev.buyer].append(ev.seller)
        elif ev.kind == "deposit":
            bound[ev.buyer] += len(open_sellers[ev.buyer])
            for s in open_sellers[ev.buyer]:
                bound[s] += 1
            open_sellers[ev.buyer] = []
    kinds = result.events["kind"].value_counts()
    return {"wealth": result.robots.sort_values("robot")["wealth"].tolist(), "bound": bound,
            "sales": int(kinds.get("purchase", 0)), "deposits": int(kinds.get("deposit", 0))}


def swarm(procs, out: Path, rpc: str, *extra: str):
    done = procs.run([sys.executable, "-m", "infomarket.cli", "ros", "swarm", *RUN, "--out", out, "--rpc", rpc, *extra])
    assert done.returncode == 0, done.stderr[-3000:] + done.stdout[-2000:]
    report = json.loads((out / "report.json").read_text())
    report["stdout"] = done.stdout
    return report


def check_ledger(report: dict, engine: dict) -> None:
    assert engine["sales"] > 0 and engine["deposits"] > 0  # the comparison proves something
    assert report["on_chain_matches_engine"] is True
    assert report["light_contracts"] == engine["sales"] and report["deposits"] == engine["deposits"]
    for row, wealth, bound in zip(report["balances"], engine["wealth"], engine["bound"]):
        assert row["engine"] == pytest.approx(wealth, abs=1e-12)
        assert abs(row["on_chain"] * 1e9 - wealth * 1e9) <= bound + 0.5, row


def test_agents_in_lock_step_reach_the_engines_ledger(procs, tmp_path, rpc, engine):
    report = swarm(procs, tmp_path, rpc)
    check_ledger(report, engine)
    assert report["processes"] == ROBOTS and report["restarted_agents"] == 0
    assert report["messages"]["offer"] >= engine["sales"] and report["messages"]["acceptance"] >= engine["sales"]
    assert report["gas"]["reveal_mean"] > 0 and report["gas"]["deposit_mean"] > 0
    keys = [tmp_path / "agents" / f"robot_{i}" / "key" for i in range(ROBOTS)]
    assert all(k.stat().st_mode & 0o777 == 0o600 for k in keys)
    assert len({k.read_text() for k in keys}) == ROBOTS  # each robot its own key


def test_killed_agent_dropped_messages_and_hostile_ones_lose_nothing(procs, tmp_path, rpc, engine):
    """SIGKILL robot 2 (the seller) in the middle of a sale, lose a fifth of every agent's messages, and send
    malformed, forged and replayed messages before every sale: the ledger is still the engine's, each sale
    revealed once, the restarted agent kept its key, and every hostile message was refused and logged."""
    key = tmp_path / "agents" / "robot_2" / "key"
    report = swarm(procs, tmp_path, rpc, "--fault", "kill:2@555", "--fault", "drop:0.2", "--fault", "hostile")
    check_ledger(report, engine)
    assert report["restarted_agents"] == 1 and report["processes"] == ROBOTS
    assert "robot 2's agent killed (SIGKILL) in the middle of a sale" in report["stdout"]
    assert report["balances"][2]["address"] == Account.from_key(bytes.fromhex(key.read_text())).address
    assert report["messages"]["retries"] > 0  # the drops were made up for by sending again
    assert report["refused_messages"] > 0  # notices on /market/done (themselves subject to the drops)
    logs = "".join((tmp_path / "agents" / f"robot_{i}.log").read_text() for i in range(ROBOTS))
    refused = [line for line in logs.splitlines() if ": refused " in line]
    assert len(refused) >= engine["sales"]  # three hostile messages are sent before each sale
    assert any("refused offer: malformed" in line for line in refused)
    assert any("refused offer" in line and "signed by" in line for line in refused)  # forged
    assert any("refused acceptance" in line and "replayed" in line for line in refused)
    assert key.stat().st_mode & 0o777 == 0o600


def test_ctrl_c_ends_every_process_of_the_swarm(procs, tmp_path):
    """Ctrl-C once the agents run: the swarm ends, and no agent or chain node of its session is left (the
    swarm starts its own node here)."""
    proc = procs.cli("ros", "swarm", "fig4C", "--robots", "2", "--steps", "100000", "--out", tmp_path,
                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    for line in proc.stdout:
        if "running" in line:
            break
    assert procs.leftovers(proc)  # the agents and the node are running
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=HANG)
    assert proc.returncode != 0
    assert procs.leftovers(proc) == []
