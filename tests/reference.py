"""A plain, slow, deliberately obvious Python implementation of one environment step (docs/model.md §2-6).

Written from docs/model.md, not from the engine: no numba, no numpy arithmetic, no infomarket imports.
Robots are ``Robot`` objects holding floats and lists; angles are kept in degrees and turned with
``math.cos``/``math.sin`` at each use.  The only things shared with the engine are the start state
(positions, headings, biases, behaviours) and a copy of the run's random ``Generator``, which this
module consumes in the order the model draws: per robot in id order, a spot when one is needed
(angle, then radius), the random-walk turn (wrapped-Cauchy table) when the Lévy counter is at most 1,
a new Lévy length when the counter runs out, and the odometry noise of the move.

Supported rules: behaviours naive, sceptical, saboteur, scaboteur, greedy, free_rider, and
sceptical_free_rider; schemes delayed and outlier, with or without a stake.  ``stop_time``,
``cooldown`` and ``fuel_cost`` must be 0 (their timing is documented apart, docs/model.md).
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

FOOD, NEST = 0, 1
EXPLORING, SEEKING_FOOD, SEEKING_NEST = 0, 1, 2
#: a seller whose balance is short of the stake by float rounding only (e.g. 1 - 25 x 0.04) can pay:
#: the exact (integer) ledger of the real contract would accept it.
ROUNDING = 1e-9

# behaviour name -> (buy rule, sell rule)
RULES = {
    "naive": ("naive", "honest"),
    "sceptical": ("sceptical", "honest"),
    "saboteur": ("naive", "rotated"),
    "scaboteur": ("sceptical", "rotated"),
    "greedy": ("naive", "age_one"),
    "free_rider": ("naive", "nothing"),
    "sceptical_free_rider": ("sceptical", "nothing"),
}


def rotate(x: float, y: float, deg: float) -> tuple[float, float]:
    """Counter-clockwise rotation by ``deg`` degrees."""
    a = math.radians(deg)
    return x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)


def angle_of(x: float, y: float) -> float:
    """Direction of (x, y) in degrees, in [0, 360)."""
    d = math.degrees(math.atan2(y, x))
    return d + 360.0 if d < 0 else d


def length(x: float, y: float) -> float:
    return math.sqrt(x * x + y * y)


def diff(a: list[float], b: list[float]) -> float:
    """Eq. 6."""
    na = length(*a)
    return 1000.0 if na == 0 else length(a[0] - b[0], a[1] - b[1]) / na


def cumulative(weights: list[float]) -> list[float]:
    total = sum(weights)
    out, acc = [], 0.0
    for w in weights:
        acc += w / total
        out.append(acc)
    out[-1] = 1.0
    return out


def draw(cdf: list[float], u: float) -> int:
    """Inverse CDF: the first index whose cumulative probability exceeds u."""
    return min(bisect.bisect_right(cdf, u), len(cdf) - 1)


@dataclass
class Entry:
    """One navigation-table entry, or one pending purchase (seller >= 0), in the robot's frame."""

    vec: list[float]
    age: int
    valid: bool = False
    seller: int = -1

    def copy(self) -> Entry:
        return Entry(list(self.vec), self.age, self.valid, self.seller)


@dataclass
class Robot:
    pos: list[float]
    heading: float  # degrees
    bias: float
    behaviour: str
    params: dict
    state: int = EXPLORING
    carrying: bool = False
    levy: int = 1
    table: list[Entry] = field(default_factory=lambda: [Entry([0.0, 0.0], 0), Entry([0.0, 0.0], 0)])
    pending: list[list[Entry]] = field(default_factory=lambda: [[], []])
    spot: list[list[float] | None] = field(default_factory=lambda: [None, None])
    last_site: int = -1
    items: int = 0
    balance: float = 1.0
    pot: float = 0.0
    transactions: list[tuple[int, int, float]] = field(default_factory=list)  # (seller, site, direction)

    # the robot's frame: x axis along its heading
    def to_frame(self, x: float, y: float) -> tuple[float, float]:
        return rotate(x, y, -self.heading)

    def to_world(self, x: float, y: float) -> tuple[float, float]:
        return rotate(x, y, self.heading)


@dataclass
class Params:
    width: float
    height: float
    radius: float
    speed: float
    comm_range: float
    noise_sd: float
    sites: list[tuple[float, float, float]]  # (x, y, radius) of food, nest
    reward: float
    info_share: float
    stake: float
    scheme: str
    theta: float
    transitory: int
    rho: float
    alpha: float
    steps: int


class Reference:
    """The whole world; ``step()`` advances it by one time step and returns that step's events as
    tuples (step, kind, buyer, seller, site, direction, x, y, age, stake, seller_x, seller_y)."""

    def __init__(self, p: Params, robots: list[Robot], rng, clock: int = 0):
        self.p = p
        self.robots = robots
        self.rng = rng
        self.clock = clock
        phi = [math.radians(d) for d in range(360)]
        self.cauchy = cumulative([(1 - p.rho ** 2) / (2 * math.pi * (1 + p.rho ** 2 - 2 * p.rho * math.cos(a)))
                                  for a in phi])
        self.levy_table = cumulative([k ** -(p.alpha + 1.0) for k in range(1, p.steps + 2)])
        self.events: list[tuple] = []
        #: every payment of the run: (step, buyer, seller, site, weight share, amount), in settlement order
        self.payments: list[tuple] = []

    # ------------------------------------------------------------------ communication
    def offer(self, s: int, site: int) -> Entry:
        """What seller s offers for ``site`` this step (its start-of-step table; valid False = nothing)."""
        r = self.robots[s]
        own = r.table[site]
        _, sell = RULES[r.behaviour]
        if sell == "nothing":
            return Entry([0.0, 0.0], 0, False)
        if sell == "rotated":
            return Entry(list(rotate(*own.vec, r.params.get("rotation_angle", 90.0))), own.age, own.valid)
        if sell == "age_one":
            return Entry(list(own.vec), 1, own.valid)
        return own.copy()

    def buy(self, b: int, s: int, site: int, offers) -> Entry | None:
        """Buyer b buys seller s's offer (docs/model.md §4); None when the seller cannot lock the stake."""
        buyer, seller = self.robots[b], self.robots[s]
        off = offers[s][site]
        rx, ry = buyer.to_frame(*seller.to_world(*off.vec))
        direction = angle_of(rx, ry)
        ox, oy = buyer.to_frame(seller.pos[0] - buyer.pos[0], seller.pos[1] - buyer.pos[1])
        if self.p.stake > 0:
            if seller.balance < self.p.stake - ROUNDING:
                self.events.append((self.clock, "refused", b, s, site, direction, rx + ox, ry + oy, off.age, 0.0,
                                    ox, oy))
                return None
            locked = min(self.p.stake, seller.balance)
            seller.balance -= locked
            buyer.pot += locked
        buyer.transactions.append((s, site, direction))
        self.events.append((self.clock, "purchase", b, s, site, direction, rx + ox, ry + oy, off.age, self.p.stake,
                            ox, oy))
        return Entry([rx + ox, ry + oy], off.age, True, s)

    @staticmethod
    def combined(own: Entry, bought: Entry) -> Entry:
        """Eqs. 4-5: each side weighted by the other's age; age the floor of the mean."""
        total = own.age + bought.age
        if total == 0:
            vec = [(own.vec[0] + bought.vec[0]) / 2, (own.vec[1] + bought.vec[1]) / 2]
        else:
            vec = [(own.age * bought.vec[k] + bought.age * own.vec[k]) / total for k in range(2)]
        return Entry(vec, total // 2, True)

    def candidates(self, b: int, nbrs: list[int], site: int, offers) -> list[int]:
        """Neighbours with a valid offer, freshest first, ties by id."""
        return sorted((s for s in nbrs if offers[s][site].valid), key=lambda s: (offers[s][site].age, s))

    def naive_buy(self, b: int, nbrs, new: list[Entry], offers) -> None:
        for site in (FOOD, NEST):
            for s in self.candidates(b, nbrs, site, offers):
                if offers[s][site].age >= new[site].age:
                    break
                got = self.buy(b, s, site, offers)
                if got is not None:
                    if new[site].valid:
                        new[site] = self.combined(new[site], got)
                    else:
                        new[site] = Entry(got.vec, (new[site].age + got.age) // 2, True)
                    break

    def sceptical_buy(self, b: int, nbrs, new: list[Entry], offers) -> None:
        r = self.robots[b]
        threshold = r.params.get("threshold", 0.25)
        for site in (FOOD, NEST):
            pending = r.pending[site]
            for s in self.candidates(b, nbrs, site, offers):
                if offers[s][site].age >= new[site].age:
                    break
                if any(p.seller == s for p in pending):
                    continue
                got = self.buy(b, s, site, offers)
                if got is None:
                    continue
                if not new[site].valid or diff(new[site].vec, got.vec) < threshold:
                    if new[site].valid:
                        new[site] = self.combined(new[site], got)
                    else:
                        new[site] = Entry(got.vec, (new[site].age + got.age) // 2, True)
                    pending.clear()
                    continue
                agreeing = next((p for p in pending if diff(p.vec, got.vec) < threshold), None)
                if agreeing is not None:
                    new[site] = self.combined(agreeing, got)
                    pending.clear()
                else:
                    pending.append(got)

    # ------------------------------------------------------------------ motion
    def inside(self, x: float, y: float, cx: float, cy: float, rad: float) -> bool:
        return math.hypot(x - cx, y - cy) < rad

    def off_arena(self, x: float, y: float) -> bool:
        p = self.p
        return x + p.radius >= p.width or x - p.radius < 0 or y + p.radius >= p.height or y - p.radius < 0

    def forage(self, i: int) -> None:
        r, p = self.robots[i], self.p
        site = NEST if r.carrying else FOOD
        cx, cy, rad = p.sites[site]
        if r.spot[site] is None and self.inside(*r.pos, cx, cy, rad):
            a = self.rng.random() * 2 * math.pi
            d = rad * math.sqrt(self.rng.random())
            r.spot[site] = [cx + d * math.cos(a), cy + d * math.sin(a)]
        if r.spot[site] is None or not self.inside(*r.pos, *r.spot[site], p.radius):
            return
        r.spot[site] = None
        if site == FOOD:
            r.carrying = True
            return
        r.carrying = False
        if self.clock >= p.transitory:  # the original counts from the step equal to the transitory period
            r.items += 1
        self.pay(i)

    def pay(self, i: int) -> None:
        """Deposit by robot i (docs/model.md §5)."""
        r, p = self.robots[i], self.p
        r.balance += p.reward
        pot, r.pot = r.pot, 0.0
        r.balance += pot
        tx = r.transactions
        if p.scheme == "delayed":
            weights = [1.0] * len(tx)
        else:
            weights = []
            for _, site, d in tx:
                close = 0
                for _, site2, d2 in tx:
                    gap = abs(d - d2) % 360.0
                    if site2 == site and min(gap, 360.0 - gap) < p.theta:
                        close += 1
                weights.append(float(close))
        if tx and sum(weights) > 0:
            amount = p.info_share * p.reward + pot
            for (s, site, _), w in zip(tx, weights):
                self.robots[s].balance += amount * w / sum(weights)
                self.payments.append((self.clock, i, s, site, w / sum(weights), amount * w / sum(weights)))
            r.balance -= amount
        else:
            self.payments += [(self.clock, i, s, site, 0.0, 0.0) for s, site, _ in tx]
        r.transactions = []
        self.events.append((self.clock, "deposit", i, -1, -1, 0.0, 0.0, 0.0, 0, 0.0, 0.0, 0.0))

    def sense(self, i: int) -> None:
        r, p = self.robots[i], self.p
        for site in (FOOD, NEST):
            cx, cy, rad = p.sites[site]
            if self.inside(*r.pos, cx, cy, rad):
                tx, ty = r.spot[site] if r.spot[site] is not None else (cx, cy)
                r.table[site] = Entry(list(r.to_frame(tx - r.pos[0], ty - r.pos[1])), 0, True)
                r.last_site = site

    def update_state(self, i: int, front: bool) -> None:
        r = self.robots[i]
        food, nest = r.table
        if r.state == EXPLORING:
            if food.valid and not r.carrying:
                r.state = SEEKING_FOOD
            elif nest.valid and r.carrying:
                r.state = SEEKING_NEST
        elif r.state == SEEKING_FOOD:
            if r.carrying:
                r.state = SEEKING_NEST if nest.valid else EXPLORING
            elif length(*food.vec) < self.p.radius:
                food.valid = False
                r.state = EXPLORING
        elif r.state == SEEKING_NEST:
            if not r.carrying:
                r.state = SEEKING_FOOD if food.valid else EXPLORING
            elif length(*nest.vec) < self.p.radius:
                nest.valid = False
                r.state = EXPLORING
        if r.state != EXPLORING and front:
            r.table[FOOD if r.state == SEEKING_FOOD else NEST].valid = False
            r.state = EXPLORING

    def intended(self, i: int) -> list[float]:
        r, v = self.robots[i], self.p.speed
        if r.state != EXPLORING:
            x, y = r.table[FOOD if r.state == SEEKING_FOOD else NEST].vec
            n = length(x, y)
            return [x * v / n, y * v / n] if n > v else [x, y]
        turn = 0
        if r.levy <= 1:
            turn = draw(self.cauchy, self.rng.random())
        r.levy -= 1
        if r.levy <= 0:
            r.levy = draw(self.levy_table, self.rng.random()) + 1
        return [v * math.cos(math.radians(turn)), v * math.sin(math.radians(turn))] if turn else [v, 0.0]

    def behaviour_step(self, i: int) -> list[float]:
        r, v = self.robots[i], self.p.speed
        x, y = r.pos
        front, right, back, left = (self.off_arena(x + dx, y + dy) for dx, dy in
                                    (rotate(v, 0.0, r.heading + turn) for turn in (0.0, -90.0, 180.0, 90.0)))
        self.sense(i)
        self.update_state(i, front)
        dr = self.intended(i)
        if (front and dr[0] >= 0) or (back and dr[0] <= 0):
            dr[0] = -dr[0]
        if (right and dr[1] <= 0) or (left and dr[1] >= 0):
            dr[1] = -dr[1]
        if dr != [0.0, 0.0]:
            turn = angle_of(*dr)
            for entry in r.table + r.pending[FOOD] + r.pending[NEST]:
                entry.vec = list(rotate(entry.vec[0] - dr[0], entry.vec[1] - dr[1], -turn))
                entry.age += 1
        return dr

    def move(self, i: int, dr: list[float]) -> None:
        r, p = self.robots[i], self.p
        if dr == [0.0, 0.0]:
            return
        mx, my = rotate(*rotate(*dr, r.heading), self.rng.normal(r.bias, p.noise_sd))
        r.heading = angle_of(mx, my)
        r.pos = [min(max(r.pos[0] + mx, p.radius), p.width - p.radius),
                 min(max(r.pos[1] + my, p.radius), p.height - p.radius)]

    # ------------------------------------------------------------------ the step
    def step(self) -> list[tuple]:
        self.clock += 1
        self.events = []
        robots, n = self.robots, len(self.robots)
        nbrs = [[j for j in range(n) if j != i and math.hypot(robots[j].pos[0] - robots[i].pos[0],
                                                               robots[j].pos[1] - robots[i].pos[1]) < self.p.comm_range]
                for i in range(n)]
        offers = [[self.offer(s, site) for site in (FOOD, NEST)] for s in range(n)]
        new_tables = [[e.copy() for e in r.table] for r in robots]
        for i, r in enumerate(robots):
            buy, _ = RULES[r.behaviour]
            (self.naive_buy if buy == "naive" else self.sceptical_buy)(i, nbrs[i], new_tables[i], offers)
        for i, r in enumerate(robots):
            self.forage(i)
            r.table = new_tables[i]
            dr = self.behaviour_step(i)
            self.move(i, dr)
        return self.events
