"""Which trades the world runs at once (``schedule.py``, ``trader.py``): sales of disjoint robots
together, each robot's trades in the engine's order, a deposit alone. The expected start orders are
worked out by hand from the rule; the trader is driven through a stand-in world (no ROS 2 needed), so
what it sends and when is seen directly.
"""
from __future__ import annotations

import pytest

from infomarket.errors import InternalError
from infomarket.ros.schedule import Job, Schedule
from infomarket.ros.trader import Trader
from infomarket.ros.world import Tally


def keys(jobs):
    return [j.key for j in jobs]


def schedule(limit: int, *jobs: tuple) -> Schedule:
    s = Schedule(limit)
    for key, robots, *barrier in jobs:
        s.add(Job(key, 1, frozenset(robots), barrier=bool(barrier)))
    return s


def test_sales_of_disjoint_robots_start_together_and_one_sharing_a_robot_waits():
    s = schedule(8, (0, {0, 1}), (1, {2, 3}), (2, {1, 4}), (3, {5, 6}))
    assert keys(s.start()) == [0, 1, 3]  # 2 shares robot 1 with 0
    assert s.start() == []
    s.finish(1)
    assert s.start() == []  # 0 still holds robot 1
    s.finish(0)
    assert keys(s.start()) == [2]
    assert s.most_running == 3


def test_a_sale_never_overtakes_an_earlier_waiting_one_it_shares_a_robot_with():
    # 1 waits for 0 (robot 1); 2 touches nothing running, but shares robot 2 with the waiting 1
    s = schedule(8, (0, {0, 1}), (1, {1, 2}), (2, {2, 3}))
    assert keys(s.start()) == [0]
    s.finish(0)
    assert keys(s.start()) == [1]
    s.finish(1)
    assert keys(s.start()) == [2]


def test_a_deposit_waits_for_every_earlier_trade_and_runs_alone():
    s = schedule(8, (0, {0, 1}), (1, {2}, "deposit"), (2, {3, 4}))
    assert keys(s.start()) == [0]  # 2 does not overtake the deposit, though its robots are free
    s.finish(0)
    assert keys(s.start()) == [1]
    assert s.start() == []
    s.finish(1)
    assert keys(s.start()) == [2]


def test_the_limit_bounds_the_sales_running_and_one_runs_them_in_order():
    s = schedule(2, (0, {0, 1}), (1, {2, 3}), (2, {4, 5}))
    assert keys(s.start()) == [0, 1]
    s.finish(0)
    assert keys(s.start()) == [2]
    one = schedule(1, (0, {0, 1}), (1, {2, 3}))
    assert keys(one.start()) == [0]
    assert one.start() == []
    with pytest.raises(InternalError):
        Schedule(0)


def test_jobs_come_in_the_engines_order_and_the_oldest_step_is_known():
    s = Schedule(4)
    s.add(Job(5, 3, frozenset({0, 1})))
    with pytest.raises(InternalError):
        s.add(Job(4, 3, frozenset({2, 3})))
    s.add(Job(6, 4, frozenset({0, 2})))
    assert s.unfinished() == 2 and s.oldest_step() == 3
    s.start()
    s.finish(5)
    assert s.oldest_step() == 4
    s.start()
    s.finish(6)
    assert s.unfinished() == 0 and s.oldest_step() is None


class StandIn:
    """The world as the trader sees it: tasks go into ``sent``, outcomes are put in by the test."""

    def __init__(self):
        self.tally, self.outcomes, self.hostile, self.sent = Tally(), {}, None, []

    def send_task(self, robot, task):
        self.sent.append((task["id"], task["kind"]))

    def spin(self, seconds=0.05):
        pass


def sale(step, buyer, seller, kind="purchase"):
    return {"kind": kind, "step": step, "buyer": buyer, "seller": seller, "site": 0, "x": 0.0, "y": 0.0, "age": 1,
            "seller_x": 0.0, "seller_y": 0.0}


def test_the_trader_sends_disjoint_sales_at_once_and_records_each_buyers_in_the_engines_order():
    world = StandIn()
    trader = Trader(world, None, [f"0x{i}" for i in range(6)], None, retry=1e9, window=1)
    for task_id, ev in enumerate([sale(1, 0, 1), sale(1, 2, 3), sale(1, 0, 4), sale(2, 5, 3, "refused")]):
        trader.event(task_id, ev)
    trader.pump()
    # 0 and 1 at once; 2 waits for 0 (buyer 0), 3 for 1 (robot 3)
    assert world.sent == [(0, "buy"), (0, "sell"), (1, "buy"), (1, "sell")]
    assert trader.behind(2)  # a trade of step 1 is unfinished: with a window of 1, step 2 is the last
    world.outcomes[1] = {"refused": False, "gas": 7}  # the later sale ends first
    trader.pump()
    assert world.sent[4:] == [(3, "buy"), (3, "sell")]
    world.outcomes[0] = {"refused": False, "gas": 5}
    trader.pump()
    assert world.sent[6:] == [(2, "buy"), (2, "sell")]
    world.outcomes[3] = {"refused": True, "gas": 0}
    world.outcomes[2] = {"refused": False, "gas": 6}
    trader.drain()
    assert trader.open_sellers == [[1, 4], [], [3], [], [], []]
    assert trader.sales == 3 and trader.trades == 4 and world.tally.refusals_confirmed == 1
    assert world.tally.disagreements == [] and sorted(world.tally.reveal_gas) == [5, 6, 7]
    assert trader.schedule.most_running == 2 and not trader.behind(2)
