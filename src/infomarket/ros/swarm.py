"""``infomarket ros swarm``: the chain node, one agent process per robot, the engine as the world, and
``report.json`` saying whether every robot's balance on chain equals its wealth in the engine.

Faults: ``kill:R@S`` SIGKILLs robot R's agent at step S (in the middle of its sale when it sells then)
and starts it again (same key, same state folder); ``drop:P`` makes every agent lose that share of the
messages it sends; ``hostile`` sends malformed, forged and replayed messages before every sale
(``hostile.py``). Ctrl-C (or SIGTERM) ends every process of the swarm at once: each is SIGKILLed by process
group, and dies with the swarm anyway.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import replace
from pathlib import Path
from statistics import mean

from .. import load_experiment
from ..engine.simulation import Simulation
from ..engine.world import EVENT_NAMES, headings
from ..errors import ConfigError, SimulationError
from ..evm.cli import demo_config
from ..evm.evm_replay import REPLAY_NO_EXPIRY, BalanceRow, market_params
from ..evm.market import ChainMarket, connect
from ..evm.units import to_units
from . import launch
from .faults import Faults
from .hostile import Hostile
from .schedule import PARALLEL, WINDOW
from .trader import Trader
from .world import RETRY, World


#: Steps between two looks at the world's incoming messages when no trade is under way (while one is,
#: every step looks). A look costs about as much as publishing a step (rclpy rebuilds its wait set of
#: every topic); messages wait meanwhile in their queues (100 deep), and between trades only stragglers
#: arrive (a duplicate offer or outcome, to be counted).
DRAIN_EVERY = 10


def prepare(experiment: str, robots: int, steps: int, scheme: str, faults: Faults):
    """The scaled experiment and the contract's parameters, refused with a ConfigError when not runnable."""
    config = demo_config(load_experiment(experiment), robots, steps, scheme)
    if config.chain.enabled:
        raise ConfigError("the ROS swarm runs the market on a real chain node: use an experiment without the "
                          "chain model")
    params = market_params(config)
    if params.stake_expiry:
        raise ConfigError("stake expiry needs one block per step, and a chain node mines one block per "
                          "transaction: use a payment section without stake_expiry")
    params = replace(params, stake_expiry=REPLAY_NO_EXPIRY)  # the engine's "never" (the contract needs one)
    if faults.kill and not (0 <= faults.kill[0] < robots and 1 <= faults.kill[1] <= steps):
        raise ConfigError(f"--fault kill:{faults.kill[0]}@{faults.kill[1]}: robots are 0..{robots - 1}, "
                          f"steps 1..{steps}")
    return config, params


class Swarm:
    """The run's processes and state; ``run()`` returns the report, ``close()`` ends every process."""

    def __init__(self, config, params, seed: int, out: Path, rpc: str | None, faults: Faults, *,
                 per_process: int = 1, controlled: list[int] = (), controller_timeout: float | None = None,
                 retry: float = RETRY, parallel: int = PARALLEL, window: int = WINDOW):
        self.config, self.params, self.seed, self.out, self.rpc, self.faults = config, params, seed, out, rpc, faults
        self.n = config.swarm.robots
        #: the robots each agent process hosts (one each by default)
        self.groups = [list(range(i, min(i + per_process, self.n))) for i in range(0, self.n, per_process)]
        self.controlled, self.controller_timeout = set(controlled), controller_timeout
        for robots in self.groups:
            if 0 < len(self.controlled.intersection(robots)) < len(robots):
                raise ConfigError(f"robots {robots} share an agent process: --controlled names all of them or none")
        self.retry, self.parallel, self.window = retry, parallel, window
        self.node = None
        self.agents: list = []  # one process per group
        self.world = None
        self.restarted = 0
        self.welcomed: dict[int, str] = {}

    def _agent(self, group: int):
        """Start the process of group ``group`` (a robot's agent, or several robots' in one process)."""
        robots = self.groups[group]
        controlled = [r in self.controlled for r in robots]
        argv = launch.agent_argv(robots, self.out / "agents", self.rpc, self.market.address, self.faults.drop,
                                 self.seed, all(controlled), self.controller_timeout)
        return launch.start(argv, self.out / "agents" / launch.log_name(robots))

    def _group_of(self, robot: int) -> int:
        return next(g for g, robots in enumerate(self.groups) if robot in robots)

    def _check(self) -> None:
        """Welcome every agent that says hello (again, after a restart); fail if one died by itself."""
        for robot, hello in list(self.world.hellos.items()):
            del self.world.hellos[robot]
            if robot in self.welcomed and hello["address"] != self.welcomed[robot]:
                raise SimulationError(f"robot {robot}'s agent came back with another key ({hello['address']})")
            self.welcomed.setdefault(robot, hello["address"])
            self.world.send_task(robot, {"kind": "welcome"})
        for robots, proc in zip(self.groups, self.agents):
            if proc.poll() is not None:
                raise SimulationError(f"the agent process of robots {robots} exited with status "
                                      f"{proc.returncode}; see {self.out / 'agents' / launch.log_name(robots)}")

    def run(self, say=print) -> dict:
        t0 = time.perf_counter()
        self.out.mkdir(parents=True, exist_ok=True)
        if self.rpc is None:
            self.node, self.rpc = launch.start_node(self.out / "chain-node.log")
            say(f"chain node: Hardhat at {self.rpc} (up after {time.perf_counter() - t0:.1f} s)")
        chain = connect(self.rpc)
        self.market = market = ChainMarket.deploy(self.params, backend=chain, seed=self.seed)
        say(f"market contract at {market.address}; starting {len(self.groups)} agent processes for {self.n} robots")
        # A swarm of its own: another swarm on this machine (a parallel test, another user) must not
        # hear these topics. The agents inherit both variables.
        os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))
        os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        self.world = world = World(self.n)
        self.agents = [self._agent(g) for g in range(len(self.groups))]
        while len(self.welcomed) < self.n:
            world.spin()
            self._check()
        addresses = [self.welcomed[i] for i in range(self.n)]
        chain.fund(addresses)
        for a in addresses:
            market.grant_wealth(a, to_units(self.config.payment.initial_wealth))
        if self.faults.hostile:
            world.hostile = Hostile(world, market.domain, addresses)
        trader = Trader(world, market, addresses, self.params, on_wait=self._check, retry=self.retry,
                        parallel=self.parallel, window=self.window)
        sim = Simulation(self.config, self.seed, record_events=True)
        say(f"agents registered ({', '.join(str(p.pid) for p in self.agents)}) after {time.perf_counter() - t0:.1f} s; "
            f"running {self.config.steps} steps")
        comm = float(self.config.robot.communication_range)
        seen = 0
        self.seconds = {"setup": time.perf_counter() - t0, "world": 0.0, "trading": 0.0}
        for step in range(1, self.config.steps + 1):
            t1 = time.perf_counter()
            sim.step(1)
            w = sim.world
            world.publish_step(step, w.pos, headings(w), comm)
            if step % DRAIN_EVERY == 0 and not trader.live:
                world.spin(0)
            t2 = time.perf_counter()
            self.seconds["world"] += t2 - t1
            if self.faults.kill and step == self.faults.kill[1]:
                trader.drain()  # the kill lands between sales, or in the middle of this robot's own
                self._arm_kill(step, [int(w.ev_seller[k]) for k in range(seen, int(w.ev_count[0]))
                                      if EVENT_NAMES[int(w.ev_kind[k])] == "purchase"], say)
            for k in range(seen, int(w.ev_count[0])):
                ev = {"kind": EVENT_NAMES[int(w.ev_kind[k])], "step": int(w.ev_step[k]), "buyer": int(w.ev_buyer[k]),
                      "seller": int(w.ev_seller[k]), "site": int(w.ev_site[k]), "x": float(w.ev_x[k]),
                      "y": float(w.ev_y[k]), "age": int(w.ev_age[k]), "seller_x": float(w.ev_sx[k]),
                      "seller_y": float(w.ev_sy[k])}
                if ev["kind"] in ("purchase", "refused", "deposit"):
                    trader.event(k, ev)
            seen = int(w.ev_count[0])
            trader.wait(lambda: not trader.behind(step))  # noqa: B023 - called before the loop moves on
            self.seconds["trading"] += time.perf_counter() - t2
        t3 = time.perf_counter()
        trader.drain()
        self.seconds["trading"] += time.perf_counter() - t3
        return self._report(sim.result(), trader, addresses, time.perf_counter() - t0)

    def _arm_kill(self, step: int, sellers: list[int], say) -> None:
        """The ``kill`` fault at ``step``: if the robot sells in this step, in the middle of its first sale
        (as its acceptance goes out, whether or not it has revealed yet); else at once."""
        robot = self.faults.kill[0]

        def kill(where: str) -> None:
            group = self._group_of(robot)
            launch.kill(self.agents[group])
            self.agents[group] = self._agent(group)
            self.restarted += 1
            say(f"step {step}: robot {robot}'s agent killed (SIGKILL) {where} and started again")

        if robot not in sellers:
            kill("between sales")
            return

        def on_acceptance(seller: int) -> None:
            if seller == robot:
                self.world.acceptance_seen = None
                kill("in the middle of a sale")

        self.world.acceptance_seen = on_acceptance

    def _report(self, result, trader, addresses, wall: float) -> dict:
        market, tally = self.market, self.world.tally
        wealth = result.robots.sort_values("robot")["wealth"].to_numpy()
        rows = [BalanceRow(i, market.balance_of(a), float(wealth[i]), trader.bound[i]) for i, a in enumerate(addresses)]
        # A sale's payout waits for the buyer's deposit: until then the chain must hold it as an open record
        # of the buyer's round trip, naming its seller (a run without a deposit is checked by these too).
        open_chain = [[c[0] for c in market.contributors(a)] for a in addresses]
        open_engine = [[addresses[s] for s in sellers] for sellers in trader.open_sellers]
        sales = trader.sales
        stepping = self.seconds["world"] + self.seconds["trading"]
        gas_total = sum(tally.reveal_gas) + sum(tally.deposit_gas)
        protocol = sum(tally.messages[k] for k in ("offer", "acceptance", "deposit", "task", "done"))

        def avg(xs):
            return mean(xs) if xs else None

        return {
            "robots": self.n, "steps": self.config.steps, "seed": self.seed, "rpc": self.rpc,
            "ros_domain_id": os.environ["ROS_DOMAIN_ID"],
            "market": market.address, "processes": len({p.pid for p in self.agents}),
            "restarted_agents": self.restarted, "robots_per_process": max(map(len, self.groups)),
            "controlled": sorted(self.controlled), "declined": tally.declined,
            "light_contracts": sales, "refusals_confirmed": tally.refusals_confirmed,
            "deposits": len(tally.deposit_gas),
            "messages": {**tally.messages, "protocol": protocol,
                         "protocol_per_sale": protocol / sales if sales else None, "retries": tally.retries},
            "gas": {"reveal_mean": avg(tally.reveal_gas), "deposit_mean": avg(tally.deposit_gas), "total": gas_total,
                    "per_sale": gas_total / sales if sales else None},
            "seconds_per_sale": avg(tally.sale_seconds),
            "trades": trader.trades, "trades_per_second": round(trader.trades / stepping, 3) if stepping else None,
            "parallel": {"limit": self.parallel, "window_steps": self.window,
                         "most_running": trader.schedule.most_running},
            "refused_messages": len(tally.refused_messages),
            "refused_examples": [r.get("what", "") + ": " + r.get("reason", "") for r in tally.refused_messages[:10]],
            "disagreements": tally.disagreements,
            "on_chain_matches_engine": (all(r.ok for r in rows) and open_chain == open_engine
                                        and not tally.disagreements),
            "faults": {"kill": list(self.faults.kill) if self.faults.kill else None, "drop": self.faults.drop,
                       "hostile": self.faults.hostile},
            "wall_seconds": round(wall, 2), "seconds": {k: round(v, 2) for k, v in self.seconds.items()},
            "balances": [{"robot": r.robot, "address": addresses[r.robot], "on_chain": r.chain_units / 1e9,
                          "engine": r.expected, "diff_units": round(r.diff_units, 3), "bound_units": r.bound_units,
                          "ok": r.ok, "open_purchases": {"on_chain": len(open_chain[r.robot]),
                                                         "engine": len(open_engine[r.robot]),
                                                         "same_sellers": open_chain[r.robot] == open_engine[r.robot]}}
                         for r in rows],
        }

    def close(self) -> None:
        """End every process of the swarm (agents first, then the chain node)."""
        for proc in self.agents:
            launch.stop(proc)
        launch.stop(self.node)
        if self.world is not None:
            self.world.close()
            self.world = None


def write_report(report: dict, out: Path) -> Path:
    path = out / "report.json"
    path.write_text(json.dumps(report, indent=2) + "\n")
    return path
