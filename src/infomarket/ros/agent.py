"""One robot's market agent: a ROS 2 node, in its own process, holding the robot's own key.

It carries out what the robot's behaviour decided (a task from the world: sell to a buyer, buy from a
seller, deposit) by the paper's protocol: the seller signs an offer (EIP-712) committing to the path
information and sends it to the buyer; the buyer checks it against what it expects, signs the
acceptance and sends the light contract's bytes back; the seller checks the buyer's signature, dry-runs
the reveal and sends ``revealInformation`` from its own account to the contract on the JSON-RPC node;
for a deposit the robot signs ``Deposit(robot, trip)`` for the nest. Every step is idempotent: a task or
message seen again (a retry after a drop or a restart) is answered from the state on disk, and the
contract refuses a second reveal of the same light contract, so nothing is paid twice.

With a controller (``controller=True``), the robot's own code has the last word: the agent asks it
before it signs an offer and before it accepts one it heard (``decide.py``); a no ends the sale there,
reported as declined.

Anything malformed, forged (a signature by another key, a seller or buyer other than expected) or
replayed (a message for a sale that is over) is refused, logged and reported on ``/market/done`` as a
``refused`` notice; the agent keeps running.
"""
from __future__ import annotations

import json
import os
import random
import sys
import time
from pathlib import Path

from eth_account import Account

from ..evm.errors import ContractRevert
from ..evm.market import ChainMarket, connect
from ..evm.protocol import (
    LightContract,
    Offer,
    PathInfo,
    ProtocolError,
    accept_offer,
    acceptance_digest,
    checksum,
    sign_deposit,
    sign_offer,
)
from . import wire
from .decide import Decisions
from .state import AgentState, load_or_create_key

#: Blocks an offer stays valid (the contract's ``maxValidity`` is 256).
BLOCKS_VALID = 200
#: Seconds between two hellos until the world answers.
HELLO_EVERY = 0.5
#: Offers for tasks not yet seen kept at most (they may overtake their task on another topic).
EARLY_OFFERS = 16


class MarketAgent:
    """The node and the protocol; ``spin()`` runs it until the process is stopped."""

    def __init__(self, robot: int, folder: Path, rpc: str, market_address: str, *, drop: float = 0.0,
                 seed: int = 0, controller: bool = False, controller_timeout: float | None = None):
        import rclpy
        from nav_msgs.msg import Odometry
        from rclpy.signals import SignalHandlerOptions
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Float64MultiArray, String, UInt8MultiArray

        self.robot, self.folder = robot, folder
        self.account = Account.from_key(load_or_create_key(folder))
        self.state = AgentState(folder)
        self.market = ChainMarket(connect(rpc), market_address, self.account)
        self.domain = self.market.domain
        self.rng = random.Random(f"{seed}/{robot}/{time.time_ns()}")
        self.drop = drop
        self.welcomed = False
        self.step = -1
        self.latest_buy = -1
        self.early: dict[int, list[bytes]] = {}
        self.pose = None
        self.sensed: list[float] = []
        self._String, self._Bytes = String, UInt8MultiArray
        if not rclpy.ok():  # once per process: several agents may share one (``host``)
            rclpy.init(args=None, signal_handler_options=SignalHandlerOptions.NO)
        self.rclpy = rclpy
        self.node = node = rclpy.create_node(f"market_agent_{robot}")
        q = wire.qos()
        node.create_subscription(String, wire.task(robot), self._on_task, q)
        node.create_subscription(UInt8MultiArray, wire.offers(robot), self._on_offer, q)
        node.create_subscription(UInt8MultiArray, wire.acceptances(robot), self._on_acceptance, q)
        node.create_subscription(Odometry, wire.odom(robot), self._on_odom, q)
        node.create_subscription(Float64MultiArray, wire.neighbours(robot), self._on_neighbours, q)
        node.create_subscription(Clock, wire.CLOCK, lambda m: None, q)
        self.hello = node.create_publisher(String, wire.HELLO, q)
        self.done = node.create_publisher(String, wire.DONE, q)
        self.deposits = node.create_publisher(UInt8MultiArray, wire.DEPOSIT, q)
        self._peers: dict[str, object] = {}
        node.create_timer(HELLO_EVERY, self._say_hello)
        self.decisions = None
        self._waiting: dict[tuple[int, str], object] = {}  # what to resume once a question is answered
        if controller:
            asks = node.create_publisher(String, wire.ask(robot), q)
            self.decisions = Decisions(lambda text: asks.publish(String(data=text)), controller_timeout)
            node.create_subscription(String, wire.decision(robot), self._on_decision, q)
            node.create_timer(0.2, self._on_timeout)
        self._recover()

    # -- sending --------------------------------------------------------------------------------------
    def _send(self, publisher, msg) -> None:
        """Publish, or lose the message with probability ``drop`` (the ``drop`` fault)."""
        if self.drop and self.rng.random() < self.drop:
            return
        publisher.publish(msg)

    def _peer(self, topic: str):
        if topic not in self._peers:
            self._peers[topic] = self.node.create_publisher(self._Bytes, topic, wire.qos())
        return self._peers[topic]

    def _bytes(self, data: bytes):
        return self._Bytes(data=list(data))

    def _report(self, **fields) -> None:
        self._send(self.done, self._String(data=json.dumps({"robot": self.robot, **fields})))

    def refuse(self, what: str, why: str) -> None:
        """Log a refused message and tell the world; the agent goes on."""
        print(f"robot {self.robot}: refused {what}: {why}", file=sys.stderr, flush=True)
        self._report(kind="refused", what=what, reason=why)

    def _say_hello(self) -> None:
        if not self.welcomed:
            self._send(self.hello, self._String(data=json.dumps(
                {"robot": self.robot, "address": self.account.address, "pid": os.getpid()})))

    # -- sensing --------------------------------------------------------------------------------------
    def _on_odom(self, msg) -> None:
        self.pose = (msg.pose.pose.position.x, msg.pose.pose.position.y)

    def _on_neighbours(self, msg) -> None:
        self.sensed = list(msg.data)

    # -- tasks from the behaviour ------------------------------------------------------------------------
    def _on_task(self, msg) -> None:
        try:
            t = wire.decode_json(msg.data, "kind")
        except wire.WireError as exc:
            return self.refuse("task", str(exc))
        kind = t["kind"]
        if kind == "welcome":
            self.welcomed = True
            return None
        self.step = max(self.step, int(t.get("step", -1)))
        if kind == "sell":
            return self._sell(t)
        if kind == "buy":
            self.latest_buy = max(self.latest_buy, int(t["id"]))
            if self.state.get(t["id"]) is None:
                self.state.put(t["id"], {"kind": "buy", "task": t})
            for data in self.early.pop(int(t["id"]), []):
                self._accept(data)
            return None
        if kind == "deposit":
            return self._deposit(t)
        return self.refuse("task", f"unknown kind {kind!r}")

    def _sell(self, t: dict, decided: bool = False) -> None:
        rec = self.state.get(t["id"])
        if rec is not None and "result" in rec:
            return self._report(kind="done", id=t["id"], **rec["result"])
        if rec is not None and rec.get("lc"):
            return self._reveal(t["id"], rec)
        if rec is None and self.decisions is not None and not decided:
            self._waiting[(int(t["id"]), "sell")] = t
            return self.decisions.ask(t["id"], "sell", {k: t[k] for k in (
                "step", "buyer", "buyer_address", "site", "age", "x", "y")})
        if rec is None:
            info = PathInfo.from_floats(float(t["x"]), float(t["y"]))
            offer = Offer(self.account.address, int(t["site"]), int(t["age"]),
                          self.market.backend.block_number + BLOCKS_VALID, info.digest())
            rec = {"kind": "sell", "task": t, "x": info.x, "y": info.y, "salt": info.salt.hex(),
                   "offer": wire.encode_offer(t["id"], offer, sign_offer(self.account.key, self.domain, offer)).hex()}
            self.state.put(t["id"], rec)
        self._send(self._peer(wire.offers(int(t["buyer"]))), self._bytes(bytes.fromhex(rec["offer"])))
        return None

    # -- buyer's side ----------------------------------------------------------------------------------
    def _on_offer(self, msg) -> None:
        self._accept(bytes(msg.data))

    def _accept(self, data: bytes, decided: bool = False) -> None:
        try:
            task_id, offer, sig = wire.decode_offer(data)
        except wire.WireError as exc:
            return self.refuse("offer", str(exc))
        rec = self.state.get(task_id)
        if rec is None:
            if task_id > self.latest_buy and sum(map(len, self.early.values())) < EARLY_OFFERS:
                self.early.setdefault(task_id, []).append(data)  # its task may still be on its way
                return None
            return self.refuse("offer", f"task {task_id}: no purchase of this robot (unsolicited or replayed)")
        t = rec["task"]
        if rec.get("kind") != "buy" or int(t["step"]) < self.step:
            return self.refuse("offer", f"task {task_id}: not an open purchase of this robot (replayed)")
        if offer.seller != checksum(t["seller_address"]) or (offer.site, offer.age) != (t["site"], t["age"]):
            return self.refuse("offer", f"task {task_id}: not the offer this robot's behaviour chose "
                                        f"(seller {offer.seller}, site {offer.site}, age {offer.age})")
        if "result" in rec:  # declined by its controller: the same answer to a repeat
            return self._report(kind="done", id=task_id, **rec["result"])
        if "lc" not in rec and self.decisions is not None and not decided:
            self._waiting[(task_id, "buy")] = data
            return self.decisions.ask(task_id, "buy", {
                "step": t["step"], "seller": t["seller"], "seller_address": offer.seller, "site": offer.site,
                "age": offer.age, "max_block": offer.max_block, "path_hash": "0x" + offer.path_hash.hex(),
                "seller_x": t["seller_x"], "seller_y": t["seller_y"]})
        if "lc" in rec:
            lc = wire.lc_from_json(rec["lc"])
            if (lc.offer, lc.offer_signature) != (offer, sig):
                return self.refuse("offer", f"task {task_id}: a second, different offer for one sale")
        else:
            try:
                lc = accept_offer(self.account.key, self.domain, offer, sig,
                                  (float(t["seller_x"]), float(t["seller_y"])),
                                  self.market.round_trip(self.account.address))
            except ProtocolError as exc:
                return self.refuse("offer", f"task {task_id}: {exc}")
            self.state.put(task_id, {**rec, "lc": wire.lc_to_json(lc)})
        self._send(self._peer(wire.acceptances(int(t["seller"]))), self._bytes(wire.encode_acceptance(task_id, lc)))
        return None

    # -- seller's side ---------------------------------------------------------------------------------
    def _on_acceptance(self, msg) -> None:
        try:
            task_id, lc = wire.decode_acceptance(bytes(msg.data))
        except wire.WireError as exc:
            return self.refuse("acceptance", str(exc))
        rec = self.state.get(task_id)
        if rec is None or rec.get("kind") != "sell":
            return self.refuse("acceptance", f"task {task_id}: this robot made no such offer")
        if int(rec["task"]["step"]) < self.step:
            return self.refuse("acceptance", f"task {task_id}: the sale is over (replayed)")
        if "result" in rec:  # a duplicate of this step's acceptance (a retry): the outcome again
            return self._report(kind="done", id=task_id, **rec["result"])
        _, offer, sig = wire.decode_offer(bytes.fromhex(rec["offer"]))
        if (lc.offer, lc.offer_signature) != (offer, sig):
            return self.refuse("acceptance", f"task {task_id}: it does not accept this robot's offer")
        buyer = checksum(rec["task"]["buyer_address"])
        try:
            digest = acceptance_digest(self.domain, offer, lc.buyer, lc.seller_x, lc.seller_y, lc.trip)
            signer = Account._recover_hash(digest, vrs=(lc.v, int.from_bytes(lc.r, "big"), int.from_bytes(lc.s, "big")))
        except Exception as exc:  # noqa: BLE001 - a signature that recovers to nothing
            return self.refuse("acceptance", f"task {task_id}: bad signature ({type(exc).__name__})")
        if lc.buyer != buyer or signer != buyer:
            return self.refuse("acceptance",
                               f"task {task_id}: signed by {signer} for {lc.buyer}, not the buyer {buyer}")
        if not rec.get("lc"):
            rec = {**rec, "lc": wire.lc_to_json(lc)}
            self.state.put(task_id, rec)
        return self._reveal(task_id, rec)

    def _reveal(self, task_id: int, rec: dict) -> None:
        """Reveal ``rec``'s light contract and report it. A JSON-RPC chain is sent a call of every
        transaction first and raises its revert, so a refusal costs no gas (and no separate dry run)."""
        lc: LightContract = wire.lc_from_json(rec["lc"])
        info = PathInfo(int(rec["x"]), int(rec["y"]), bytes.fromhex(rec["salt"]))
        try:
            result = {"refused": False, "gas": self.market.reveal(self.account, lc, info).gas_used}
        except ContractRevert as err:
            if err.name == "InfoMarketAlreadyRevealed":  # revealed before a restart: paid once, not twice
                result = {"refused": False, "gas": 0, "recovered": True}
            elif err.name == "InfoMarketInsufficientStake":  # the sale is void by the rules
                result = {"refused": True, "gas": 0}
            else:
                result = {"refused": True, "gas": 0, "error": err.name}
        self.state.put(task_id, {**rec, "result": result})
        self._report(kind="done", id=task_id, **result)

    def _recover(self) -> None:
        """After a restart: reveal every light contract held but not revealed (the world asks again too)."""
        for task_id, rec in self.state.unrevealed():
            print(f"robot {self.robot}: recovering the light contract of task {task_id}", file=sys.stderr, flush=True)
            self._reveal(task_id, rec)

    # -- the robot's controller ------------------------------------------------------------------------
    def _on_decision(self, msg) -> None:
        try:
            settled = self.decisions.answer(msg.data)
        except wire.WireError as exc:
            return self.refuse("decision", str(exc))
        if settled is not None:
            self._resume(*settled)
        return None

    def _on_timeout(self) -> None:
        for task_id, question in self.decisions.expired():
            print(f"robot {self.robot}: no answer from the controller to {question!r} in task {task_id}: "
                  "the behaviour's decision (yes)", file=sys.stderr, flush=True)
            self._resume(task_id, question, True)

    def _resume(self, task_id: int, question: str, yes: bool) -> None:
        """Carry on with a sale once the controller (or the timeout) has answered."""
        what = self._waiting.pop((task_id, question), None)
        if what is None:
            return None
        if yes:
            return self._sell(what, decided=True) if question == "sell" else self._accept(what, decided=True)
        result = {"refused": True, "gas": 0, "declined": "seller" if question == "sell" else "buyer"}
        rec = self.state.get(task_id) or {"kind": question, "task": what}
        self.state.put(task_id, {**rec, "result": result})
        print(f"robot {self.robot}: its controller declined to {question} in task {task_id}", file=sys.stderr,
              flush=True)
        return self._report(kind="done", id=task_id, **result)

    # -- deposit ---------------------------------------------------------------------------------------
    def _deposit(self, t: dict) -> None:
        rec = self.state.get(t["id"])
        if rec is None:
            trip = self.market.round_trip(self.account.address)
            v, r, s = sign_deposit(self.account.key, self.domain, self.account.address, trip)
            rec = {"kind": "deposit", "task": t, "trip": trip, "vrs": [v, r.hex(), s.hex()]}
            self.state.put(t["id"], rec)
        v, r, s = rec["vrs"]
        data = wire.encode_deposit(t["id"], self.account.address, rec["trip"], (v, bytes.fromhex(r), bytes.fromhex(s)))
        self._send(self.deposits, self._bytes(data))

    def spin(self) -> None:
        spin([self])


def spin(agents: list[MarketAgent]) -> None:
    """Run ``agents`` (one robot's, or many robots' hosted in this one process) until the process is
    stopped: one executor serves every agent's node, in this one thread."""
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor()
    for a in agents:
        executor.add_node(a.node)
    try:
        while True:
            executor.spin_once(timeout_sec=0.1)
    finally:
        for a in agents:
            a.node.destroy_node()
        agents[0].rclpy.try_shutdown()
