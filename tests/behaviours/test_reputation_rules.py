"""The reputation-aware defences and the attacks on them do what their docstrings say.

Each rule is compared with a built-in it must equal at the extreme of its parameters (same seed, same
numbers), or with itself at other parameters, so a broken condition shows as a difference.  The swarms
are those of ``infomarket.checks`` (naive robots and the rule under test) so the kernels are shared.
"""
import numpy as np
import infomarket as im
from infomarket.ledger import LedgerEvent, replay_events

from ..shared_kernel import simulate, simulation  # the kernel the rule checks compile

NEVER = {"farm_record": 1e9, "farm_share": 1.0}   # a farmer that never reaches its threshold
ALWAYS = {"farm_record": 0.0, "farm_reputation": 0.0}  # a farmer past its threshold from the start


def _cfg(behaviour, params=None, steps=4000, scheme="outlier", stake=0.04):
    return im.Experiment.model_validate({
        "steps": steps, "transitory": 0,
        "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 20},
                                           {"behaviour": behaviour, "count": 5, "params": params or {}}]},
        "payment": {"scheme": scheme, "stake": stake}})


def _same(a, b):
    return (np.array_equal(a.robots.items_collected, b.robots.items_collected)
            and np.array_equal(a.robots.wealth, b.robots.wealth))


def test_a_farmer_past_its_threshold_is_a_scaboteur():
    farmer = simulate(_cfg("reputation_farmer", {"rotation_angle": 60.0, **ALWAYS}), 5)
    liar = simulate(_cfg("scaboteur", {"rotation_angle": 60.0}), 5)
    assert _same(farmer, liar)


def test_a_farmer_below_its_threshold_is_honest_and_switches_when_it_passes():
    honest = simulate(_cfg("sceptical"), 5)
    assert _same(simulate(_cfg("reputation_farmer", {"rotation_angle": 60.0, **NEVER}), 5), honest)
    farming = simulate(_cfg("reputation_farmer", {"rotation_angle": 60.0, "farm_record": 1.0,
                                                     "farm_reputation": 0.5, "farm_share": 1.0}), 5)
    assert not _same(farming, honest)  # its record passed the threshold during the run: it lied


def test_the_surfer_lies_at_most_margin_times_theta():
    capped = simulate(_cfg("theta_surfer", {"rotation_angle": 90.0, "margin": 0.5, "theta": 30.0}), 6)
    assert _same(capped, simulate(_cfg("scaboteur", {"rotation_angle": 15.0}), 6))
    small = simulate(_cfg("theta_surfer", {"rotation_angle": 10.0, "margin": 0.5, "theta": 30.0}), 6)
    assert _same(small, simulate(_cfg("scaboteur", {"rotation_angle": 10.0}), 6))


def test_against_the_adaptive_contract_the_surfer_follows_its_reputation():
    # theta_min = theta: the adaptive cap is theta whatever the reputation, as without adaptation
    flat = {"rotation_angle": 90.0, "margin": 0.5, "theta": 30.0, "theta_min": 30.0}
    assert _same(simulate(_cfg("theta_surfer", {**flat, "adaptive": 1.0}), 6),
                 simulate(_cfg("theta_surfer", {**flat, "adaptive": 0.0}), 6))
    # theta_min = 2: the cap is 2 + 28 x reputation < 30 once its record is below perfect
    steep = {**flat, "theta_min": 2.0}
    assert not _same(simulate(_cfg("theta_surfer", {**steep, "adaptive": 1.0}), 6),
                     simulate(_cfg("theta_surfer", {**steep, "adaptive": 0.0}), 6))


def _pending_and_purchases(params, seed=7, steps=2000):
    """The most pending purchases any reputation sceptic held, and how many purchases they made."""
    sim = simulation(_cfg("reputation_sceptic", params, steps=steps), seed, record_events=True)
    most = 0
    for _ in range(steps // 10):
        sim.step(10)
        most = max(most, int(sim.world.pend_count[20:].max()))
    ev = sim.result().events
    return most, int(((ev.kind == "purchase") & (ev.buyer >= 20)).sum())


def test_the_reputation_sceptic_believes_trusted_sellers_at_once():
    pending, bought = _pending_and_purchases({"trust_reputation": 0.0, "distrust_reputation": 0.0,
                                              "min_record": 0.0})
    assert bought > 0 and pending == 0  # everyone is trusted: nothing ever waits for confirmation
    pending, bought = _pending_and_purchases({})
    assert bought > 0 and pending > 0   # by default most sellers are not: purchases wait


def test_the_reputation_sceptic_never_buys_from_distrusted_sellers():
    _, bought = _pending_and_purchases({"distrust_reputation": 1.0, "min_record": 0.0})
    assert bought == 0  # every reputation is below 1 (Laplace), so every seller is ignored


def test_adaptive_theta_with_a_flat_threshold_is_the_paper_scheme():
    rng = np.random.default_rng(3)
    events = []
    for _ in range(200):
        buyer = int(rng.integers(6))
        if rng.random() < 0.15:
            events.append(LedgerEvent("deposit", buyer))
        else:
            events.append(LedgerEvent("purchase", buyer, (buyer + int(rng.integers(1, 6))) % 6,
                                      int(rng.integers(2)), float(rng.normal(0, 40)) % 360))
    paper = replay_events(events, 6, scheme="outlier", stake=0.04, params={"theta": 30.0})
    flat = replay_events(events, 6, scheme="adaptive_outlier", stake=0.04, params={"theta": 30.0, "theta_min": 30.0})
    steep = replay_events(events, 6, scheme="adaptive_outlier", stake=0.04, params={"theta": 30.0, "theta_min": 5.0})
    assert np.array_equal(paper.balances, flat.balances)
    assert not np.allclose(paper.balances, steep.balances)
