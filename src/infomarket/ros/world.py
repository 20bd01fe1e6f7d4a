"""The engine as the world: it steps the simulation, publishes what the robots sense, and has the agents
carry out the trades its behaviours decided (``trader.py``), those of disjoint robots at once, each
robot's in the engine's order (lock step, within a window of steps).

Design: the decisions (who sells to whom, what, when a robot deposits) come from the engine, which
runs the experiment's registered behaviours exactly as ``simulate`` does; the agents carry them out as
separate processes over ROS 2 and the chain, with their own keys, signatures and transactions. So
the chain's ledger must equal the engine's, which ``report.json`` checks. (An agent driven by a robot's
own controller would receive the same task messages from that controller instead; the swarm command
always uses the engine's behaviours.)

Each step: advance the engine one step; publish ``/clock`` and every robot's odometry and sensed
neighbours; then hand the step's ledger events to the trader: a sale (buy task to the buyer, sell task
to the seller, wait for the seller's outcome) or a deposit (deposit task, wait for the robot's
signature, co-sign as the nest, ``buyItem`` and ``settle``). A task without an answer is sent again
every ``RETRY`` seconds: a dropped message or a restarted agent costs time, not money.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from . import wire

#: Seconds of ROS time one simulated step stands for (the /clock the world publishes).
STEP_SECONDS = 0.1
#: Seconds without an answer after which a task is sent again.
RETRY = 1.0



@dataclass
class Tally:
    """What the run cost, counted by the world (it listens to every market topic)."""

    messages: dict = field(default_factory=lambda: {"offer": 0, "acceptance": 0, "deposit": 0, "task": 0, "done": 0,
                                                    "hello": 0, "sensing": 0})
    reveal_gas: list = field(default_factory=list)
    deposit_gas: list = field(default_factory=list)
    sale_seconds: list = field(default_factory=list)
    refused_messages: list = field(default_factory=list)
    refusals_confirmed: int = 0
    declined: int = 0  # sales a robot's controller declined
    retries: int = 0
    disagreements: list = field(default_factory=list)


class World:
    """The world's ROS 2 node (publishers to every robot, listeners on the market topics)."""

    def __init__(self, robots: int, hostile=None):
        import rclpy
        from nav_msgs.msg import Odometry
        from rclpy.signals import SignalHandlerOptions
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Float64MultiArray, String, UInt8MultiArray

        rclpy.init(args=None, signal_handler_options=SignalHandlerOptions.NO)
        self.rclpy = rclpy
        self.node = node = rclpy.create_node("market_world")
        self.n = robots
        self.step = 0
        self.tally = Tally()
        self.hostile = hostile
        self._types = (String, Odometry, Float64MultiArray, Clock)
        q = wire.qos()
        self.clock = node.create_publisher(Clock, wire.CLOCK, q)
        self.odom = [node.create_publisher(Odometry, wire.odom(i), q) for i in range(robots)]
        self.near = [node.create_publisher(Float64MultiArray, wire.neighbours(i), q) for i in range(robots)]
        self.tasks = [node.create_publisher(String, wire.task(i), q) for i in range(robots)]
        self.hellos: dict[int, dict] = {}
        self.outcomes: dict[int, dict] = {}
        self.signed: dict[int, tuple] = {}
        #: called with the seller's number when an acceptance goes to it (the mid-sale ``kill`` fault)
        self.acceptance_seen = None
        node.create_subscription(String, wire.HELLO, self._on_hello, q)
        node.create_subscription(String, wire.DONE, self._on_done, q)
        node.create_subscription(UInt8MultiArray, wire.DEPOSIT, self._on_deposit, q)
        for i in range(robots):
            node.create_subscription(UInt8MultiArray, wire.offers(i), lambda m: self._count("offer"), q)
            node.create_subscription(UInt8MultiArray, wire.acceptances(i), lambda m, i=i: self._on_acceptance(i), q)

    def _on_acceptance(self, seller: int) -> None:
        self._count("acceptance")
        if self.acceptance_seen is not None:
            self.acceptance_seen(seller)

    def _count(self, kind: str) -> None:
        self.tally.messages[kind] += 1

    def _on_hello(self, msg) -> None:
        self._count("hello")
        try:
            h = wire.decode_json(msg.data, "robot", "address", "pid")
            self.hellos[int(h["robot"])] = h
        except (wire.WireError, ValueError, TypeError):
            pass

    def _on_done(self, msg) -> None:
        self._count("done")
        try:
            d = wire.decode_json(msg.data, "robot", "kind")
        except wire.WireError:
            return
        if d["kind"] == "refused":
            self.tally.refused_messages.append(d)
        elif d["kind"] == "done" and "id" in d:
            self.outcomes.setdefault(int(d["id"]), d)

    def _on_deposit(self, msg) -> None:
        self._count("deposit")
        try:
            task_id, robot, trip, vrs = wire.decode_deposit(bytes(msg.data))
        except wire.WireError:
            return
        self.signed.setdefault(task_id, (robot, trip, vrs))

    def spin(self, seconds: float = 0.05) -> None:
        self.rclpy.spin_once(self.node, timeout_sec=seconds)

    def send_task(self, robot: int, task: dict) -> None:
        self._count("task")
        self.tasks[robot].publish(self._types[0](data=json.dumps(task)))

    def publish_step(self, step: int, pos: np.ndarray, heading_deg: np.ndarray, comm_range: float) -> None:
        """``/clock`` and, per robot, its odometry and the robots within communication range (own frame)."""
        _, Odometry, Float64MultiArray, Clock = self._types
        self.step = step
        ns = round(step * STEP_SECONDS * 1e9)
        clock = Clock()
        clock.clock.sec, clock.clock.nanosec = ns // 10**9, ns % 10**9
        self.clock.publish(clock)
        for i in range(self.n):
            o = Odometry()
            o.header.stamp = clock.clock
            o.header.frame_id, o.child_frame_id = "arena", f"robot_{i}"
            o.pose.pose.position.x, o.pose.pose.position.y = float(pos[i, 0]), float(pos[i, 1])
            half = math.radians(float(heading_deg[i])) / 2
            o.pose.pose.orientation.z, o.pose.pose.orientation.w = math.sin(half), math.cos(half)
            self.odom[i].publish(o)
            d = pos - pos[i]
            near = np.flatnonzero((np.hypot(d[:, 0], d[:, 1]) < comm_range) & (np.arange(self.n) != i))
            c, s = math.cos(-math.radians(float(heading_deg[i]))), math.sin(-math.radians(float(heading_deg[i])))
            rows = [v for j in near for v in (float(j), c * d[j, 0] - s * d[j, 1], s * d[j, 0] + c * d[j, 1])]
            self.near[i].publish(Float64MultiArray(data=rows))
        self.tally.messages["sensing"] += 1 + 2 * self.n

    def close(self) -> None:
        self.node.destroy_node()
        self.rclpy.try_shutdown()
