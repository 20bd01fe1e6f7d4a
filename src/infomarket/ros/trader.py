"""Carries out the engine's ledger events through the agents and the contract, those of disjoint robots
at once.

A sale takes a few hundred milliseconds of messages, signatures and a transaction, most of it spent
waiting on other processes (the two agents, the chain node); one after the other, the trades of a
25-robot swarm would take hours while the world waits. So the trader keeps every unfinished event in
a ``Schedule`` (``schedule.py`` says why the ledger stays the engine's) and, each time it is pumped,
starts every sale that may run now, takes in the outcomes that have come, and sends again the tasks of
sales that have waited ``retry`` seconds (then longer each time, ``BACKOFF``). A deposit runs alone, as
before: the world waits for the robot's signature, co-signs as the nest and sends ``buyItem`` and
``settle``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

from ..evm.protocol import checksum, deposit_digest, sign_deposit
from .schedule import PARALLEL, QUEUE, WINDOW, Job, Schedule
from .world import RETRY, World

#: Looks at the incoming messages per pump at most, while answers keep coming.
LOOKS = 20
#: A sale's tasks are sent again after ``retry`` seconds without its outcome, then after twice as long
#: each time, up to this many times ``retry``: on a loaded machine a sale among several at once may take
#: longer than ``retry`` with nothing lost, and resending at a fixed pace would only add work.
BACKOFF = 4


@dataclass
class _Sale:
    """A sale under way: its two tasks, when they were last sent and how long until they are sent again,
    when it began."""

    ev: dict
    buy: dict
    sell: dict
    sent: float
    wait: float
    began: float


class Trader:
    """The engine's events in, the agents' trades and the nest's deposits out."""

    def __init__(self, world: World, market, addresses: list[str], params, on_wait=None, retry: float = RETRY,
                 parallel: int = PARALLEL, window: int = WINDOW):
        self.world, self.market, self.addresses, self.params = world, market, addresses, params
        self.retry, self.window = retry, window
        self.on_wait = on_wait or (lambda: None)
        self.schedule = Schedule(parallel)
        self.events: dict[int, dict] = {}  # waiting, by task id
        self.live: dict[int, _Sale] = {}  # running sales
        self.open_sellers: list[list[int]] = [[] for _ in addresses]
        self.bound = [0] * len(addresses)
        self.sales = 0
        self.trades = 0  # sales carried out: made, refused or declined (deposits apart)

    # -- the world's side --------------------------------------------------------------------------------
    def event(self, task_id: int, ev: dict) -> None:
        """Queue one of the engine's events (in the engine's order)."""
        deposit = ev["kind"] == "deposit"
        robots = {int(ev["buyer"])} if deposit else {int(ev["buyer"]), int(ev["seller"])}
        self.schedule.add(Job(task_id, int(ev["step"]), frozenset(robots), barrier=deposit))
        self.events[task_id] = ev

    def behind(self, step: int) -> bool:
        """Whether the world must wait before stepping past ``step``: a trade more than ``window`` steps
        old is unfinished, or too many are."""
        oldest = self.schedule.oldest_step()
        return oldest is not None and (oldest <= step - self.window or self.schedule.unfinished() >= QUEUE)

    def wait(self, done) -> None:
        """Spin and pump until ``done()``."""
        self.pump()
        while not done():
            self.world.spin()
            self.on_wait()
            self.pump()

    def drain(self) -> None:
        """Carry out every event queued so far."""
        self.wait(lambda: not self.schedule.unfinished())

    def pump(self) -> None:
        """Take in what has come, start what may start, send again what has waited too long."""
        if self.live:
            self._look()
        while True:
            finished = [key for key in self.live if key in self.world.outcomes]
            for key in finished:
                self._finish(key)
            started = self.schedule.start()
            for job in started:
                if job.barrier:
                    self.deposit(job.key, int(self.events.pop(job.key)["buyer"]), job.step)
                    self.schedule.finish(job.key)
                else:
                    self._begin(job.key, self.events.pop(job.key))
            if not finished and not started:
                break
        now = time.monotonic()
        for sale in self.live.values():
            if now - sale.sent > sale.wait:
                self.world.tally.retries += 1
                self._send(sale)
                sale.sent, sale.wait = now, min(2 * sale.wait, BACKOFF * self.retry)

    def _look(self) -> None:
        """Take in the messages waiting for the world, without waiting for more."""
        heard = self._heard()
        for _ in range(LOOKS):
            self.world.spin(0)
            if self._heard() == heard:
                return
            heard = self._heard()

    def _heard(self) -> int:
        return sum(n for kind, n in self.world.tally.messages.items() if kind not in ("sensing", "task"))

    # -- sales -------------------------------------------------------------------------------------------
    def _begin(self, task_id: int, ev: dict) -> None:
        buyer, seller = int(ev["buyer"]), int(ev["seller"])
        common = {"id": task_id, "step": int(ev["step"]), "site": int(ev["site"]), "age": int(ev["age"]),
                  "buyer": buyer, "seller": seller, "buyer_address": self.addresses[buyer],
                  "seller_address": self.addresses[seller]}
        buy = {**common, "kind": "buy", "seller_x": float(ev["seller_x"]), "seller_y": float(ev["seller_y"])}
        sell = {**common, "kind": "sell", "x": float(ev["x"]), "y": float(ev["y"])}
        if self.world.hostile is not None:
            self.world.hostile(buyer, seller, task_id, common["site"], common["age"], common["step"])
        sale = self.live[task_id] = _Sale(ev, buy, sell, time.monotonic(), self.retry, time.perf_counter())
        self._send(sale)

    def _send(self, sale: _Sale) -> None:
        self.world.send_task(sale.buy["buyer"], sale.buy)
        self.world.send_task(sale.sell["seller"], sale.sell)

    def _finish(self, task_id: int) -> None:
        sale = self.live.pop(task_id)
        self.schedule.finish(task_id)
        ev, out = sale.ev, self.world.outcomes.pop(task_id)
        buyer, seller = int(ev["buyer"]), int(ev["seller"])
        self.trades += 1
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
        self.world.tally.sale_seconds.append(time.perf_counter() - sale.began)
        if out.get("gas"):
            self.world.tally.reveal_gas.append(int(out["gas"]))
        self.open_sellers[buyer].append(seller)

    # -- deposits ----------------------------------------------------------------------------------------
    def _until(self, done, resend) -> None:
        """Spin until ``done()``; ``resend()`` every ``retry`` seconds meanwhile (nothing else runs)."""
        resend()
        last = time.monotonic()
        while not done():
            self.world.spin()
            self.on_wait()
            if time.monotonic() - last > self.retry:
                self.world.tally.retries += 1
                resend()
                last = time.monotonic()

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
