"""The environment the ROS 2 wheels need, set by the package itself so that a user only types the command.

The wheels (``ros-rclpy[fastrtps]`` and the message packages) put their shared libraries in the
environment's ``lib`` folder, or in a ``ros_runtime_libs`` folder next to the Python packages, depending
on the build. The dynamic loader reads ``LD_LIBRARY_PATH`` only when a process starts, and rcl reads
``RMW_IMPLEMENTATION`` when it initialises, so both must be in place before the process starts:
``ensure()`` re-executes the command once with them when ``rclpy`` cannot be loaded as it is, and
every child process (agents, the chain node) is started with ``child_env()``.
"""
from __future__ import annotations

import os
import site
import sys
from pathlib import Path

RMW = "rmw_fastrtps_cpp"
#: Set in a re-executed process, so that a failed import is reported instead of re-executing forever.
_MARK = "INFOMARKET_ROS_ENV"
WHEELS = "ros-rclpy[fastrtps] 9.1.2, ros-std-msgs, ros-geometry-msgs, ros-nav-msgs (CPython 3.11)"


def library_dirs() -> list[str]:
    """Folders holding the wheels' shared libraries (``librcl.so``), in search order."""
    roots = [Path(p) for p in (*site.getsitepackages(), site.getusersitepackages()) if p]
    found = [str(r / "ros_runtime_libs") for r in roots if (r / "ros_runtime_libs").is_dir()]
    lib = Path(sys.prefix) / "lib"
    if (lib / "librcl.so").exists():
        found.append(str(lib))
    return found


def child_env(extra: dict | None = None) -> dict:
    """``os.environ`` with the ROS 2 variables set (and ``extra`` over it), for a process to be started."""
    env = {**os.environ, **(extra or {})}
    dirs = library_dirs()
    paths = [p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(dirs + [p for p in paths if p not in dirs])
    env["RMW_IMPLEMENTATION"] = RMW
    env[_MARK] = "1"
    return env


def missing() -> str | None:
    """Why the ROS 2 client cannot be used in this process (None when it can)."""
    os.environ.setdefault("RMW_IMPLEMENTATION", RMW)
    try:
        import rclpy  # noqa: F401 - imported only to learn whether the wheels load
        from geometry_msgs.msg import PoseArray  # noqa: F401 - likewise, each message package
        from nav_msgs.msg import Odometry  # noqa: F401 - likewise, each message package
        from rosgraph_msgs.msg import Clock  # noqa: F401 - likewise, each message package
        from std_msgs.msg import String  # noqa: F401 - likewise, each message package
    except Exception as exc:  # noqa: BLE001 - an ImportError, a missing shared library (OSError), ...
        return f"{type(exc).__name__}: {exc}"
    return None


def ensure() -> str | None:
    """Make ``rclpy`` usable in this process: nothing if it already is; else re-execute this command line
    once with ``child_env()`` (does not return); the reason when even that did not help."""
    reason = missing()
    if reason is None:
        return None
    if os.environ.get(_MARK) or not library_dirs():
        return f"infomarket ros needs the ROS 2 wheels ({WHEELS}; pip install 'infomarket[ros]'): {reason}"
    os.execve(sys.executable, [sys.executable, *sys.orig_argv[1:]], child_env())
    return None  # not reached
