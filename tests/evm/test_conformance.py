"""One conformance suite, two ledgers: the simulated ledger (the engine's compiled ledger code, through
``infomarket.ledger.replay``) and the contract (through ``infomarket.evm.replay``, every purchase a
real light contract, every deposit ``buyItem`` plus ``settle``).

``LedgerConformance`` is written once; each subclass says how to run an event sequence on its ledger.
Both must reproduce the 32 payment vectors of the original simulator (tests/fixtures) and, on random
event sequences (up to 25 robots and 1 000 operations, stake expiry on or off), the exact rational
model of tests/evm/exact_ledger.py: the simulated ledger to 1e-9 token, the contract within its
rounding bound (one unit per share a robot took part in). The property runs 200 examples on the
simulated ledger, 80 on the contract over revm (every transaction signed and sent: most of this file's
time), and a smaller sample over py-evm (a pure-Python EVM takes about a second per hundred transactions).
Every payment-rule mutant of the contract tried fails those 80 within the first few examples
(docs/testing.md); they do not draw every scheme and expiry pair the 200 draw (delayed payment with expiry
3 is one they miss), which the simulated ledger's 200 and the payment vectors cover.
``capped_outlier`` (cap 1 or 2, with and without stake) has random sequences of its own, 100 on the
simulated ledger and 40 on revm, so that the other schemes' draws do not depend on it; among them,
sellers over their cap in round trips settled at their expiry.
"""
from __future__ import annotations

import json
import random
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from infomarket.evm.market import MarketParams, connect
from infomarket.evm.evm_replay import FLOAT_SLACK_UNITS, ReplayMarket, replay_market, replay_on_chain
from infomarket.evm.units import TOKEN_UNIT
from infomarket.ledger.replay import replay_events

from .clients import client_copy
from .exact_ledger import SELLER_POSITION, ExactLedger, vector_for
from .node import running_node

CASES = json.loads((Path(__file__).parents[1] / "fixtures" / "payment_vectors.json").read_text())["cases"]
SCHEMES = {"delayed": ("delayed", 0.0), "outlier": ("outlier", 0.0), "outlier+stake": ("outlier", 0.04),
           "distinct": ("outlier_distinct", 0.0), "distinct+stake": ("outlier_distinct", 0.04),
           "capped": ("capped_outlier", 0.0), "capped+stake": ("capped_outlier", 0.04),
           "capped1+stake": ("capped_outlier", 0.04)}
#: The per-seller cap of each ``capped_outlier`` case (records per seller per round trip that count).
CAPS = {"capped": 2, "capped+stake": 2, "capped1+stake": 1}
#: Directions 7.3 k degrees (k < 50): no two differ by Theta = 30 within 0.1 degree, so the
#: simulation's degrees and the contract's micro-unit vectors cannot decide a pair differently.
DIRECTIONS = [round(7.3 * k % 360, 6) for k in range(50)]


def purchase(step, buyer, seller, site, direction, age, kind="purchase"):
    x, y = vector_for(direction)
    return {"kind": kind, "step": step, "buyer": buyer, "seller": seller, "site": site,
            "direction_deg": direction, "x": x, "y": y, "seller_x": SELLER_POSITION[0],
            "seller_y": SELLER_POSITION[1], "age": age}


def deposit(step, robot):
    return {"kind": "deposit", "step": step, "buyer": robot, "seller": -1, "site": -1, "direction_deg": 0.0,
            "x": 0.0, "y": 0.0, "seller_x": 0.0, "seller_y": 0.0, "age": 0}


#: The schemes the scenarios draw from: those without a cap.
UNCAPPED = tuple(sorted(set(SCHEMES) - set(CAPS)))


@st.composite
def scenarios(draw, expiries=(0, 0, 3, 10), longest=1000, schemes=UNCAPPED):
    """(robots, scheme, wealth, expiry, events): hypothesis draws the sizes and a seed, the events
    come from the seed (1 000 operations drawn one by one would exceed hypothesis' data budget);
    most sequences are short, one in eight is long (up to ``longest`` operations)."""
    robots = draw(st.integers(2, 25))
    scheme = draw(st.sampled_from(schemes))
    wealth = draw(st.sampled_from([0.05, 0.1, 1.0]))
    expiry = draw(st.sampled_from(expiries))
    length = draw(st.one_of(*[st.integers(0, 40)] * 7, st.integers(40, longest)))
    rng = random.Random(draw(st.integers(0, 2**32 - 1)))
    events, step = [], 1
    for age in range(length):
        step += rng.randrange(3)
        buyer = rng.randrange(robots)
        if rng.random() < 0.15:
            events.append(deposit(step, buyer))
        else:
            seller = (buyer + rng.randrange(1, robots)) % robots
            events.append(purchase(step, buyer, seller, rng.randrange(2), rng.choice(DIRECTIONS), age))
    return robots, scheme, wealth, expiry, events


def _case(sales, stake):
    """Robot 0 buys ``sales`` ((seller, direction) on food) in one round trip at step 1, then deposits."""
    return [purchase(1, 0, seller, 0, d, k) for k, (seller, d) in enumerate(sales)] + [deposit(2, 0)]


_REPEAT = [(1, 10.0), (2, 15.0), (3, 20.0)] + [(4, 100.0)] * 5  # a saboteur sells one vector 5 times
_COPY = [(1, 10.0), (2, 15.0), (3, 20.0)] + [(5, 12.0)] * 6  # a seller copies the honest direction 6 times
F = Fraction
#: (scheme, events, every robot's balance after the deposit), by hand (share 0.5 of a reward of 1).
DISTINCT_CASES = [
    # eq. 7 counts transactions: honest 3 each, the repeated vector 5 each (x5): the saboteur takes 25/34.
    ("outlier", _case(_REPEAT, 0.0), [F(3, 2), 1 + F(1, 2) * F(3, 34), 1 + F(1, 2) * F(3, 34),
                                      1 + F(1, 2) * F(3, 34), 1 + F(1, 2) * F(25, 34)]),
    # one seller, one voice: honest 3 each, each repeat 1/5: the saboteur takes 1/10, as if it sold once.
    ("distinct", _case(_REPEAT, 0.0), [F(3, 2), 1 + F(3, 20), 1 + F(3, 20), 1 + F(3, 20), 1 + F(1, 20)]),
    # the copier's 6 records weigh 4/6 each: 4 of 16 in all, one honest seller's share (stakes shared too).
    ("distinct+stake", _case(_COPY, 0.04),
     [F(3, 2), *[1 - F(1, 25) + F(86, 100) / 4] * 3, F(1), 1 - 6 * F(1, 25) + F(86, 100) / 4]),
]


#: Robot 0 buys from 1 (10 degrees) and 2 (15) at step 1, from 3 (20), 4 (25) and 5 (100) at step 6, and
#: deposits at step 6 or at step 20 (stake expiry 5). At the start of step 6 the round trip of 1 and 2
#: expires: it is settled as a deposit settles it, the buyer paying the share 0.5 from its balance: 1 and
#: 2 agree under every scheme, 0.25 each plus their stakes (1.25). 3, 4 and 5 open a new round trip, paid
#: 0.5 plus their stakes by weight, at the deposit at step 6, or at its expiry at the start of step 11
#: (the buyer's balance, 0.5, pays the share again) before the deposit at step 20 finds it empty: 20 and
#: 25 degrees agree (2 similar records, or 2 distinct sellers), 100 is alone (1): 2/5, 2/5, 1/5. The
#: buyer paid the share twice for one reward either way: it ends at 1.
_LATE = [purchase(1, 0, 1, 0, 10.0, 0), purchase(1, 0, 2, 0, 15.0, 1), purchase(6, 0, 3, 0, 20.0, 2),
         purchase(6, 0, 4, 0, 25.0, 3), purchase(6, 0, 5, 0, 100.0, 4)]


def _late(scheme, stake, weights):
    second = [1 - stake + (F(1, 2) + 3 * stake) * w for w in weights]
    return [(scheme, _LATE + [deposit(step, 0)], [F(1), F(5, 4), F(5, 4), *second]) for step in (6, 20)]


LATE_CASES = [*_late("delayed", 0, [F(1, 3)] * 3), *_late("outlier", 0, [F(2, 5), F(2, 5), F(1, 5)]),
              *_late("outlier+stake", F(1, 25), [F(2, 5), F(2, 5), F(1, 5)]),
              *_late("distinct", 0, [F(2, 5), F(2, 5), F(1, 5)]),
              *_late("distinct+stake", F(1, 25), [F(2, 5), F(2, 5), F(1, 5)])]


def simulated_params(scheme: str) -> dict | None:
    """The simulated ledger's payment parameters for a case's scheme."""
    name, _ = SCHEMES[scheme]
    if name == "delayed":
        return None
    return {"theta": 30.0, **({"cap": float(CAPS[scheme])} if scheme in CAPS else {})}


#: ``capped_outlier`` by hand (share 0.5 of a reward of 1, Theta 30, every robot starting with 1). A void
#: record gets its stake back; the counted ones share the rest, share + pot - void stakes, by eq. 7 among
#: themselves (each counted record's count of similar counted records, C their sum).
CAPPED_CASES = [
    # cap 2, a seller over it: 1@10, 2@15, 3@100 three times; 3's third record is void. Counts 2, 2 (10 and
    # 15 agree), 2, 2 (3's two counted ones agree): C = 8. Pot 5 x 0.04 = 0.2, amount 0.7, rest
    # 0.7 - 0.04 = 0.66, 0.66 x 2/8 = 0.165 per counted record: 1 and 2 end at 1 - 0.04 + 0.165 = 1.125,
    # 3 at 1 - 0.12 + 2 x 0.165 + 0.04 = 1.25 (under eq. 7 alone it would take 9/13 of 0.7); the buyer
    # 1 + 1 + 0.2 - 0.7 = 1.5.
    ("capped+stake", _case([(1, 10.0), (2, 15.0)] + [(3, 100.0)] * 3, 0.04),
     [F(3, 2), F(9, 8), F(9, 8), F(5, 4)]),
    # cap 1, the saboteur of _REPEAT sells one vector 5 times: 4 void. Counts 3, 3, 3 (10, 15, 20 agree), 1:
    # C = 10. Pot 8 x 0.04 = 0.32, amount 0.82, rest 0.82 - 4 x 0.04 = 0.66: the honest 0.66 x 3/10 = 0.198
    # each, 1 - 0.04 + 0.198 = 1.158; the saboteur 1 - 0.2 + 0.066 + 4 x 0.04 = 1.026.
    ("capped1+stake", _case(_REPEAT, 0.04), [F(3, 2), F(1158, 1000), F(1158, 1000), F(1158, 1000), F(1026, 1000)]),
    # cap 2, two sellers with records on both sites (the cap counts both): 1 food@10, 2 food@20, 1 nest@200,
    # 1 food@15 (1's third: void), 2 nest@210, 2 food@25 (2's third: void), 1 nest@205 (void), 3 food@100.
    # Counted: food 10, 20 (count 2 each), 100 (1); nest 200, 210 (2 each): C = 9. Pot 8 x 0.04 = 0.32,
    # amount 0.82, rest 0.82 - 3 x 0.04 = 0.7, 0.7/9 per count. Seller 1: 1 - 4 x 0.04 + 4 x 0.7/9 + 2 x
    # 0.04 = 0.92 + 14/45; seller 2: 1 - 3 x 0.04 + 4 x 0.7/9 + 0.04 = 0.92 + 14/45; seller 3: 0.96 + 7/90.
    ("capped+stake", [purchase(1, 0, 1, 0, 10.0, 0), purchase(1, 0, 2, 0, 20.0, 1), purchase(1, 0, 1, 1, 200.0, 2),
                      purchase(1, 0, 1, 0, 15.0, 3), purchase(1, 0, 2, 1, 210.0, 4), purchase(1, 0, 2, 0, 25.0, 5),
                      purchase(1, 0, 1, 1, 205.0, 6), purchase(1, 0, 3, 0, 100.0, 7), deposit(2, 0)],
     [F(3, 2), F(92, 100) + F(14, 45), F(92, 100) + F(14, 45), F(96, 100) + F(7, 90)]),
    # cap 2, the void record is the one eq. 7 would make the outlier: 1@10, 1@15, 2@20, 1@200 (1's third).
    # Counts 3, 3, 3: C = 9. Pot 0.16, amount 0.66, rest 0.62. Seller 1: 1 - 0.12 + 6 x 0.62/9 + 0.04 = 4/3
    # (its far record is not slashed: void, its stake comes back); seller 2: 1 - 0.04 + 3 x 0.62/9 = 7/6.
    ("capped+stake", _case([(1, 10.0), (1, 15.0), (2, 20.0), (1, 200.0)], 0.04), [F(3, 2), F(4, 3), F(7, 6)]),
    # without stakes a void record gets nothing: cap 2, 1@10 three times, 2@50: counts 2, 2, 1 (C = 5),
    # 0.5 x 2/5 = 0.2 for each of 1's counted records, 0.1 for 2.
    ("capped", _case([(1, 10.0)] * 3 + [(2, 50.0)], 0.0), [F(3, 2), F(14, 10), F(11, 10)]),
]


#: Expired round trips under the cap (stake expiry 5, cap 1), by hand.
LATE_CAPPED = [
    # 1@10 at step 1 expires its round trip at the start of step 6: settled alone, the buyer paying the share,
    # 0.5 + 0.04 to seller 1 (1.5), the buyer left with 0.5. Then 2@20, 2@25 (2's second: void) and 3@100
    # at step 6, deposited at step 6: the rule's weights add up to 0.5 + 0.12 = 0.62, 0.04 for the void
    # record (its stake back), the rest 0.58 split 1 : 1 (counts 1 and 1): 2 ends at 1 - 0.08 + 0.29 + 0.04,
    # 3 at 0.96 + 0.29, the buyer at 0.5 + 1 - 0.5 = 1.
    ("capped1+stake", [purchase(1, 0, 1, 0, 10.0, 0), purchase(6, 0, 2, 0, 20.0, 1),
                       purchase(6, 0, 2, 0, 25.0, 2), purchase(6, 0, 3, 0, 100.0, 3), deposit(6, 0)],
     [F(1), F(3, 2), F(5, 4), F(5, 4)]),
    # A buyer that cannot pay the whole share: 1@10 (step 1) and 2@20 (step 6) each expire a round trip, at
    # steps 6 and 11, 0.5 + 0.04 to their sellers (1.5 each), the buyer's 1 gone in shares. 3@30, 3@35
    # (void) and 4@100 at step 11 expire at step 16 with a share of 0 (the buyer's balance): the amount is
    # the pot, 0.12, paid by the rule's weights of 0.62 (void 0.04, counted 0.29 each): the void record
    # 0.12 x 0.04/0.62 = 6/775, a counted one 0.12 x 0.29/0.62 = 87/1550. The deposit at step 16 finds the
    # round trip empty: the buyer keeps the reward, 1.
    ("capped1+stake", [purchase(1, 0, 1, 0, 10.0, 0), purchase(6, 0, 2, 0, 20.0, 1), purchase(11, 0, 3, 0, 30.0, 2),
                       purchase(11, 0, 3, 0, 35.0, 3), purchase(11, 0, 4, 0, 100.0, 4), deposit(16, 0)],
     [F(1), F(3, 2), F(3, 2), F(92, 100) + F(87, 1550) + F(6, 775), F(96, 100) + F(87, 1550)]),
]


def exact_run(robots, scheme, wealth, expiry, events) -> tuple[ExactLedger, list[bool]]:
    """The rational model, and whether each purchase is accepted (the simulation decides refusals:
    the event kinds fed to the ledgers are taken from this model, as the simulator's log would be)."""
    name, stake = SCHEMES[scheme]
    exact = ExactLedger(robots, name, Fraction(1), Fraction(1, 2), Fraction(str(stake)), Fraction(30),
                        Fraction(str(wealth)), expiry, CAPS.get(scheme, 0))
    accepted = []
    for ev in events:
        exact.advance(ev["step"])
        if ev["kind"] == "deposit":
            exact.deposit(ev["buyer"])
        else:
            ok = exact.purchase(ev["buyer"], ev["seller"], ev["site"], Fraction(str(ev["direction_deg"])), ev["step"])
            ev["kind"] = "purchase" if ok else "refused"
            accepted.append(ok)
    return exact, accepted


class LedgerConformance:
    """The behaviour every ledger must show; subclasses implement ``run``."""

    examples = 200
    #: random sequences drawn under ``capped_outlier`` alone (the examples above draw the other schemes)
    capped_examples = 100
    expiries = (0, 0, 3, 10)
    longest = 1000

    def run(self, robots: int, scheme: str, wealth: float, expiry: int, events: list[dict]) -> list[float]:
        """Replay ``events`` on a fresh ledger; each robot's final balance, in tokens."""
        raise NotImplementedError

    def tolerance(self, bound: int) -> float:
        """How far (tokens) a balance may be from the exact model, given its rounding bound."""
        raise NotImplementedError

    def check_by_hand(self, scheme, events, expected, *, expiry: int = 0, bound: int | None = None,
                      exact: bool = True) -> None:
        """Replay hand-computed ``events`` (copies): every balance is ``expected`` within the ledger's rounding
        for ``bound`` shares (default: the accepted purchases), and, with ``exact``, the rational model's
        balances are ``expected`` exactly, so the hand calculation checks the model too."""
        mine = [dict(e) for e in events]
        balances = self.run(len(expected), scheme, 1.0, expiry, mine)
        shares = sum(1 for e in mine if e["kind"] == "purchase") if bound is None else bound
        for i, value in enumerate(expected):
            assert balances[i] == pytest.approx(float(value), abs=self.tolerance(shares) + 1e-9), i
        if exact:
            model, _ = exact_run(len(expected), scheme, 1.0, expiry, [dict(e) for e in events])
            assert model.balance == expected

    @pytest.mark.parametrize("case", CASES, ids=[f"{i}-{c['scheme']}" for i, c in enumerate(CASES)])
    def test_payment_vectors_of_the_original_simulator(self, case):
        events = [purchase(1, case["buyer"], t["seller"], 0 if t["site"] == "food" else 1, t["direction_deg"], k,
                           "purchase" if t["accepted"] else "refused") for k, t in enumerate(case["transactions"])]
        events.append(deposit(2, case["buyer"]))
        balances = self.run(case["robots"], case["scheme"], case["initial_wealth"], 0, events)
        n = len(case["transactions"])
        for i in range(case["robots"]):
            assert balances[i] == pytest.approx(case["balances_after_deposit"][str(i)],
                                                abs=self.tolerance(n) + 1e-9)

    @pytest.mark.parametrize(("scheme", "events", "expected"), DISTINCT_CASES,
                             ids=[f"{c[0]}-{k}" for k, c in enumerate(DISTINCT_CASES)])
    def test_one_seller_one_voice_by_hand(self, scheme, events, expected):
        """Shared hand-computed cases: repetition and copying sellers, under eq. 7 and outlier_distinct."""
        self.check_by_hand(scheme, events, expected, exact=False)

    @pytest.mark.parametrize(("scheme", "events", "expected"), LATE_CASES,
                             ids=[f"{c[0]}-{c[1][-1]['step']}" for c in LATE_CASES])
    def test_a_late_deposit_pays_every_record_by_hand(self, scheme, events, expected):
        """Shared hand-computed cases of stake expiry: round trips settled at their expiry, a deposit after."""
        if self.expiries == (0,):
            pytest.skip("this ledger replays one block per transaction: no stake expiry")
        self.check_by_hand(scheme, events, expected, expiry=5, bound=5)

    @pytest.mark.parametrize(("scheme", "events", "expected"), CAPPED_CASES,
                             ids=[f"{c[0]}-{k}" for k, c in enumerate(CAPPED_CASES)])
    def test_the_per_seller_cap_by_hand(self, scheme, events, expected):
        """``capped_outlier``: a seller over its cap, cap 1, two sellers on both sites, a void outlier."""
        self.check_by_hand(scheme, events, expected)

    @pytest.mark.parametrize(("scheme", "events", "expected"), LATE_CAPPED, ids=["void-after-expired", "short-share"])
    def test_a_late_deposit_under_the_cap_by_hand(self, scheme, events, expected):
        if self.expiries == (0,):
            pytest.skip("this ledger replays one block per transaction: no stake expiry")
        self.check_by_hand(scheme, events, expected, expiry=5)

    def test_random_event_sequences_agree_with_the_exact_model(self):
        @settings(max_examples=self.examples, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
        @given(scenarios(self.expiries, self.longest))
        def check(scenario):
            robots, scheme, wealth, expiry, events = scenario
            exact, _ = exact_run(robots, scheme, wealth, expiry, events)
            balances = self.run(robots, scheme, wealth, expiry, events)
            for i in range(robots):
                assert abs(balances[i] - float(exact.balance[i])) <= self.tolerance(exact.bound[i]), (i, scheme, expiry)

        check()

    def test_random_capped_sequences_agree_with_the_exact_model(self):
        """The same under the per-seller cap only (cap 1 or 2, with and without stake), so that every
        variant is drawn, with sellers over their cap, expired records and refusals among them."""
        @settings(max_examples=self.capped_examples, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
        @given(scenarios(self.expiries, self.longest, tuple(sorted(CAPS))))
        def check(scenario):
            robots, scheme, wealth, expiry, events = scenario
            exact, _ = exact_run(robots, scheme, wealth, expiry, events)
            balances = self.run(robots, scheme, wealth, expiry, events)
            for i in range(robots):
                assert abs(balances[i] - float(exact.balance[i])) <= self.tolerance(exact.bound[i]), (i, scheme, expiry)

        check()


class TestSimulatedLedger(LedgerConformance):
    def run(self, robots, scheme, wealth, expiry, events):
        name, stake = SCHEMES[scheme]
        replayed = replay_events(events, robots, scheme=name, initial_wealth=wealth, stake=stake,
                                 params=simulated_params(scheme), stake_expiry=expiry)
        # what the simulation would have in pots at the end (stakes of open round trips) is not a balance
        return [float(b) for b in replayed.balances]

    def tolerance(self, bound):
        return 1e-9

    def test_random_event_sequences_agree_with_the_exact_model(self):
        super().test_random_event_sequences_agree_with_the_exact_model()


class TestContractLedger(LedgerConformance):
    backend = "revm"
    examples = 80
    capped_examples = 40
    #: where the replays' markets are kept: None, each replay deploys its own (cheap on revm); else each
    #: market is deployed once on one chain per class and reverted to (``start``)
    kept_on: str | None = None

    def connect(self):
        return connect(backend=self.backend)

    def start(self, robots: int, params: MarketParams, wealth: float) -> ReplayMarket | None:
        """The market a replay starts from, as ``replay_on_chain`` would deploy it: deployed once per
        (robots, parameters, wealth) on the class's chain, with a snapshot of the chain right after, and
        that snapshot reverted to when it comes again (which drops every later snapshot: a node keeps a
        snapshot only until it is reverted to, so it is taken again)."""
        if self.kept_on is None:
            return None
        cls = type(self)
        if cls.__dict__.get("_kept_on") != self.kept_on:
            cls._kept_on, cls._chain, cls._kept = self.kept_on, self.connect(), {}
        key, kept = (robots, params, wealth), cls._kept
        if key in kept:
            ready, snapshot = kept[key]
            cls._chain.revert(snapshot)
            for later in list(kept)[list(kept).index(key):]:
                del kept[later]
            kept[key] = (ready, cls._chain.snapshot())
            return replace(ready, market=client_copy(ready.market))
        ready = replay_market(robots=robots, params=params, initial_wealth=wealth, chain=cls._chain)
        kept[key] = (replace(ready, market=client_copy(ready.market)), cls._chain.snapshot())
        return ready

    def run(self, robots, scheme, wealth, expiry, events):
        name, stake = SCHEMES[scheme]
        params = MarketParams.from_floats(name, stake=stake, stake_expiry=expiry, max_records_per_seller=1000,
                                          cap=CAPS.get(scheme))
        report = replay_on_chain(events, robots=robots, params=params, initial_wealth=wealth, backend=self.backend,
                                 start=self.start(robots, params, wealth))
        assert not report.disagreements, report.disagreements[:3]
        assert report.conserved()
        return [b / TOKEN_UNIT for b in report.balances]

    def tolerance(self, bound):
        return (max(bound, 1) + FLOAT_SLACK_UNITS) / TOKEN_UNIT


class TestContractLedgerOnPyEvm(TestContractLedger):
    """The same suite on the reference EVM: every payment vector, and a small random sample."""

    backend = "py-evm"
    kept_on = "py-evm"
    examples = 4
    capped_examples = 2
    longest = 150
    expiries = (0,)  # py-evm mines one block per transaction: expiry needs one block per step (revm)


class TestContractLedgerOnNode(TestContractLedger):
    """The same suite once against a real JSON-RPC node (Hardhat Network, tools/node) that this class
    starts on a free port and stops: every payment vector, the hand-computed cases, a small random
    sample. Transactions are signed by the robots' keys and mined one per block, as on a chain."""

    examples = 4
    capped_examples = 2
    longest = 80
    expiries = (0,)  # one block per transaction: the replay's expiry needs one block per step (revm)

    @pytest.fixture(autouse=True, scope="class")
    @classmethod
    def node(cls):
        with running_node() as url:
            cls.rpc_url = url
            yield url

    @property
    def kept_on(self):
        return self.rpc_url

    def connect(self):
        return connect(self.rpc_url)

    def run(self, robots, scheme, wealth, expiry, events):
        name, stake = SCHEMES[scheme]
        params = MarketParams.from_floats(name, stake=stake, stake_expiry=expiry, max_records_per_seller=1000,
                                          cap=CAPS.get(scheme))
        report = replay_on_chain(events, robots=robots, params=params, initial_wealth=wealth, rpc_url=self.rpc_url,
                                 start=self.start(robots, params, wealth))
        assert report.backend == self.rpc_url and report.cold_storage
        assert not report.disagreements, report.disagreements[:3]
        assert report.conserved()
        return [b / TOKEN_UNIT for b in report.balances]

    def test_py_evm_charges_the_gas_a_node_charges_per_transaction(self):
        """The gas figures (docs/gas.md, the declared bound) come from py-evm: on the same calls, a real
        node charges the same gas, transaction by transaction, within 1 % (calldata differs slightly:
        the signatures are over each chain's domain)."""
        from infomarket.evm.market import ChainMarket, connect, derived_account
        from infomarket.evm.protocol import PathInfo

        def gas(backend):
            market = ChainMarket.deploy(MarketParams.from_floats("outlier_distinct", stake=0.04), backend=backend)
            robots = [derived_account("gas-check", i) for i in range(4)]
            backend.fund([r.address for r in robots])
            used = [market.grant_wealth(r.address, 10**9).gas_used for r in robots]
            for k in range(6):
                seller = robots[1 + k % 3]
                info = PathInfo.from_floats(*vector_for(7.3 * k), salt=bytes([k]) * 32)
                lc = market.light_contract(seller, robots[0], k % 2, k, info, SELLER_POSITION)
                used.append(market.reveal(seller, lc, info).gas_used)
            return used + [r.gas_used for r in market.deposit(robots[0].address)]

        reference, node = gas(connect(backend="py-evm")), gas(connect(self.rpc_url))
        assert len(reference) == len(node) == 11
        for a, b in zip(reference, node):
            assert abs(a - b) <= 0.01 * a, (reference, node)
