"""The options that place and steer the agents, refused in one message (exit status 2) when they cannot
work; none needs ROS 2."""
from __future__ import annotations

from pathlib import Path

import pytest

from infomarket.cli import build_parser
from infomarket.errors import ConfigError
from infomarket.ros import launch
from infomarket.ros.faults import Faults
from infomarket.ros.swarm import Swarm, prepare

HOST = ["ros", "host", "--state", "s", "--rpc", "http://127.0.0.1:8545", "--market", "0x" + "11" * 20]


@pytest.mark.parametrize("text, robots", [("0-2", [0, 1, 2]), ("4", [4]), ("0-1,7", [0, 1, 7]), ("9,3", [9, 3])])
def test_robot_lists(text, robots):
    assert build_parser().parse_args([*HOST, "--robots", text]).robots == robots


@pytest.mark.parametrize("text", ["", "x", "1-x", "3-1", "1,1", "0-2,2", "-1"])
def test_bad_robot_lists_are_refused(text, capsys):
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args([*HOST, "--robots", text])
    assert stop.value.code == 2
    assert "--robots" in capsys.readouterr().err


def _swarm(robots: int, **kw) -> Swarm:
    config, params = prepare("fig4C", robots, 10, "staking", Faults())
    return Swarm(config, params, 0, Path("unused"), None, Faults(), **kw)


def test_agents_are_grouped_into_processes_of_at_most_k():
    assert _swarm(5).groups == [[0], [1], [2], [3], [4]]
    assert _swarm(5, per_process=2).groups == [[0, 1], [2, 3], [4]]
    assert _swarm(3, per_process=9).groups == [[0, 1, 2]]


def test_robots_sharing_a_process_are_all_controlled_or_none():
    _swarm(3, per_process=2, controlled=[0, 1])  # robot 2 alone, uncontrolled
    with pytest.raises(ConfigError, match="share an agent process"):
        _swarm(3, per_process=2, controlled=[1])


def test_a_process_of_one_robot_runs_ros_agent_and_of_several_ros_host():
    one = launch.agent_argv([3], Path("A"), "http://n", "0xM", 0.0, 1)
    at = one.index("ros") + 1
    assert one[at:at + 5] == ["agent", "--robot", "3", "--state", str(Path("A/robot_3"))]
    assert "--controller" not in one
    many = launch.agent_argv([0, 1], Path("A"), "http://n", "0xM", 0.0, 1, True, 2.5)
    assert many[many.index("ros") + 1:many.index("ros") + 4] == ["host", "--robots", "0,1"]
    assert many[-3:] == ["--controller", "--controller-timeout", "2.5"]
    assert launch.log_name([0, 1]) == "robots_0-1.log" and launch.log_name([3]) == "robot_3.log"
