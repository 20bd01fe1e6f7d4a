"""The engine as the world: it steps the simulation, publishes what the robots sense, and has the agents
carry out the trades its behaviours decided, one at a time, before it takes the next step (lock step).

Design: the decisions (who sells to whom, what, when a robot deposits) come from the engine, which
runs the experiment's registered behaviours exactly as ``simulate`` does; the agents carry them out as
separate processes over ROS 2 and the chain, with their own keys, signatures and transactions. So
the chain's ledger must equal the engine's, which ``report.json`` checks. (An agent driven by a robot's
own controller would receive the same task messages from that controller instead; the swarm command
always uses the engine's behaviours.)

Each step: advance the engine one step; publish ``/clock`` and every robot's odometry and sensed
neighbours; then for each ledger event of the step, in the engine's order, a sale (buy task to the
buyer, sell task to the seller, wait for the seller's outcome) or a deposit (deposit task, wait for
the robot's signature, co-sign as the nest, ``buyItem`` and ``settle``). A task without an answer is
sent again every ``RETRY`` seconds: a dropped message or a restarted agent costs time, not money.
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..evm.protocol import checksum, deposit_digest, sign_deposit
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


class Trader:
    """Carries out the engine's ledger events through the agents and the contract."""

    def __init__(self, world: World, market, addresses: list[str], params, on_wait=None, retry: float = RETRY):
        self.world, self.market, self.addresses, self.params = world, market, addresses, params
        self.retry = retry
        self.on_wait = on_wait or (lambda: None)
        self.open_sellers: list[list[int]] = [[] for _ in addresses]
        self.bound = [0] * len(addresses)
        self.sales = 0

    def _until(self, done, resend) -> None:
        """Spin until ``done()``; ``resend()`` every ``retry`` seconds meanwhile."""
        resend()
        last = time.monotonic()
        while not done():
            self.world.spin()
            self.on_wait()
            if time.monotonic() - last > self.retry:
                self.world.tally.retries += 1
                resend()
                last = time.monotonic()

    def event(self, task_id: int, ev: dict) -> None:
        if ev["kind"] == "deposit":
            return self.deposit(task_id, int(ev["buyer"]), int(ev["step"]))
        return self.sale(task_id, ev)

    def sale(self, task_id: int, ev: dict) -> None:
        buyer, seller = int(ev["buyer"]), int(ev["seller"])
        common = {"id": task_id, "step": int(ev["step"]), "site": int(ev["site"]), "age": int(ev["age"]),
                  "buyer": buyer, "seller": seller, "buyer_address": self.addresses[buyer],
                  "seller_address": self.addresses[seller]}
        buy = {**common, "kind": "buy", "seller_x": float(ev["seller_x"]), "seller_y": float(ev["seller_y"])}
        sell = {**common, "kind": "sell", "x": float(ev["x"]), "y": float(ev["y"])}
        if self.world.hostile is not None:
            self.world.hostile(buyer, seller, task_id, common["site"], common["age"])

        def resend():
            self.world.send_task(buyer, buy)
            self.world.send_task(seller, sell)

        t0 = time.perf_counter()
        self._until(lambda: task_id in self.world.outcomes, resend)
        out = self.world.outcomes[task_id]
        if out.get("declined"):  # the robot's controller overruled the behaviour: the ledgers part here
            self.world.tally.declined += 1
            self.world.tally.disagreements.append(
                f"step {ev['step']}: the {out['declined']}'s controller declined the sale of robot {seller} to "
                f"robot {buyer} (the engine {'refused' if ev['kind'] == 'refused' else 'made'} it)")
            return
        expected_refusal = ev["kind"] == "refused"
        if bool(out.get("refused")) != expected_refusal or out.get("error"):
            self.world.tally.disagreements.append(
                f"step {ev['step']}: the engine {'refused' if expected_refusal else 'made'} a sale of robot {seller} "
                f"to robot {buyer}; on chain it was {'refused' if out.get('refused') else 'made'} "
                f"{out.get('error', '')}")
        if out.get("refused"):
            self.world.tally.refusals_confirmed += expected_refusal
            return
        self.sales += 1
        self.world.tally.sale_seconds.append(time.perf_counter() - t0)
        if out.get("gas"):
            self.world.tally.reveal_gas.append(int(out["gas"]))
        self.open_sellers[buyer].append(seller)

    def deposit(self, task_id: int, robot: int, step: int) -> None:
        address = self.addresses[robot]
        task = {"id": task_id, "step": step, "kind": "deposit", "robot": robot}
        self._until(lambda: self._good_signature(task_id, address), lambda: self.world.send_task(robot, task))
        _, trip, vrs = self.world.signed[task_id]
        nest = self.market.nest
        evidence = (*vrs, *sign_deposit(nest.key, self.market.domain, address, trip))
        results = [self.market.buy_item(address, evidence=evidence)]
        while self.market.pending_settlement(address)[0]:
            results.append(self.market.settle(address))
        self.world.tally.deposit_gas.append(sum(r.gas_used for r in results))
        sellers = self.open_sellers[robot]
        self.bound[robot] += len(sellers)  # each share floored: under a unit per share, either side
        for s in sellers:
            self.bound[s] += 1
        self.open_sellers[robot] = []

    def _good_signature(self, task_id: int, address: str) -> bool:
        """The robot's deposit signature arrived and is its own (anything else is dropped and awaited again)."""
        got = self.world.signed.get(task_id)
        if got is None:
            return False
        robot, trip, (v, r, s) = got
        from eth_account import Account

        try:
            signer = Account._recover_hash(deposit_digest(self.market.domain, robot, trip),
                                           vrs=(v, int.from_bytes(r, "big"), int.from_bytes(s, "big")))
        except Exception:  # noqa: BLE001 - any bad signature is one the robot did not make
            signer = None
        if robot != checksum(address) or signer != robot or trip != self.market.round_trip(address):
            del self.world.signed[task_id]
            return False
        return True
