"""Without the ROS 2 wheels, ``infomarket ros`` says so in one line with exit status 2 (after trying once
with the wheels' environment), and the rest of the tool is unaffected."""
from __future__ import annotations

import sys


def test_missing_wheels_one_line_exit_2(procs, tmp_path):
    fake = tmp_path / "rclpy"
    fake.mkdir()
    (fake / "__init__.py").write_text("raise ImportError('no ROS 2 here')\n")
    env = {"PYTHONPATH": str(tmp_path)}  # ahead of the real one: rclpy cannot be imported
    done = procs.run([sys.executable, "-m", "infomarket.cli", "ros", "swarm", "fig4C", "--out", tmp_path / "o"],
                     env=env)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "ROS 2 wheels" in lines[0] and "no ROS 2 here" in lines[0], done.stderr
    assert not (tmp_path / "o").exists()
    other = procs.run([sys.executable, "-m", "infomarket.cli", "list"], env=env)
    assert other.returncode == 0, other.stderr
