"""agents.runs: B runs stepped in one compiled call are the engine's own runs, actions reach the compiled
rules, and the observation is what the world holds (checked against simulate() and plain Python)."""
import sys

import numpy as np
import pytest

from infomarket.behaviours.attacks import NO_ENTRY_AGE
from infomarket.config import load_experiment
from infomarket.engine.simulation import simulate
from infomarket.errors import ConfigError
from infomarket.agents.observe import OBSERVATION
from infomarket.agents.runs import Runs, select_cell

SEEDS = [5, 17, 123]


@pytest.fixture(scope="module")
def cfg():
    return load_experiment("attack_search").with_overrides(steps=705, transitory=200)


@pytest.fixture(scope="module")
def runs(cfg):
    return Runs(cfg, 3)


def play(runs, seeds, interval, action=None):
    runs.reset(np.arange(len(seeds)), seeds)
    while runs.clocks.min() < runs.steps:
        if action is not None:
            runs.act(np.broadcast_to(action, (runs.size, len(runs.agents), len(action))))
        runs.advance(runs.clocks + interval)


@pytest.mark.parametrize("interval", [10, 1000])
def test_runs_at_the_configured_parameters_are_simulate_bit_for_bit(runs, cfg, interval):
    play(runs, SEEDS, interval)  # 705 is no multiple of 10: the last interval stops at the run's end
    assert (runs.clocks == 705).all()
    for b, seed in enumerate(SEEDS):
        ref = simulate(cfg, seed).robots
        np.testing.assert_array_equal(runs.worlds[b].items, ref.items_collected.to_numpy())
        np.testing.assert_array_equal(runs.worlds[b].balance, ref.wealth.to_numpy())
        assert runs.items[b] == ref.items_collected[ref.honest].sum()


def test_an_action_is_the_attackers_parameter_in_the_compiled_rule(runs, cfg):
    # the truth (rot_base 0) set as an action plays exactly the experiment configured with rot_base = 0
    truthful = cfg.model_dump()
    truthful["swarm"]["groups"][1]["params"]["rot_base"] = 0.0
    play(runs, SEEDS, 10, action=np.array([0.0, 0.0]))
    liar = [simulate(cfg, s).robots for s in SEEDS]
    for b, seed in enumerate(SEEDS):
        ref = simulate(truthful, seed).robots
        np.testing.assert_array_equal(runs.worlds[b].balance, ref.wealth.to_numpy())
        assert not np.array_equal(runs.worlds[b].balance, liar[b].wealth.to_numpy())


def test_actions_are_clipped_to_each_parameters_range(runs):
    runs.act(np.broadcast_to([500.0, -3.0], (3, len(runs.agents), 2)))
    col = runs.columns
    assert (runs.bparams[:, runs.agents][..., col] == [180.0, 0.0]).all()
    honest_rows = runs.bparams[:, runs.honest]
    assert (honest_rows[..., col] != 180.0).all()  # the honest robots' rows are left alone


def _reference_observation(w, me, steps, theta):
    """The observation row computed again in plain Python from the world's arrays."""
    n = w.pos.shape[0]
    others = n - 1
    settled, reduced = w.rep_settled[me], w.rep_reduced[me]
    row = [(settled - reduced + 1) / (settled + 2), min(settled / 100, 1), theta / 180,
           w.balance[me] / w.money[0], w.nbr_count[me] / others, float(w.carrying[me]), w.clock[0] / steps]
    for site in range(2):
        valid = w.tab_valid[me, site]
        age = w.tab_age[me, site] if valid else NO_ENTRY_AGE
        nb = w.nbr[me, :w.nbr_count[me]]
        sellers = sum(bool(w.tab_valid[j, site]) for j in nb)
        ages = [w.tab_age[j, site] if w.tab_valid[j, site] else NO_ENTRY_AGE for j in nb]
        buyers = [j for j, a in zip(nb, ages) if a > age]
        reps = [(w.rep_settled[j] - w.rep_reduced[j] + 1) / (w.rep_settled[j] + 2) for j in buyers]
        oldest = max([a for a in ages if a > age], default=0)
        row += [float(valid), min(age / 1000, 1), sellers / others, len(buyers) / others,
                np.mean(reps) if reps else 0.5, min(oldest / 1000, 1)]
    return np.array(row)


def test_the_observation_is_what_the_world_holds(runs):
    runs.reset(np.arange(3), SEEDS)
    checked = 0
    for _ in range(40):
        runs.advance(runs.clocks + 10)
        for b in range(3):
            for a, me in enumerate(runs.agents):
                ref = _reference_observation(runs.worlds[b], me, runs.steps, 30.0)  # outlier, Θ = 30°
                np.testing.assert_allclose(runs.obs[b, a], ref, rtol=1e-6, atol=1e-7)
                checked += runs.worlds[b].nbr_count[me] > 0
    assert runs.obs.shape == (3, 3, len(OBSERVATION)) and checked > 0  # some agents had neighbours


def test_a_sweep_cell_is_picked_by_its_keys():
    exp = load_experiment("attack_search")
    c = select_cell(exp, {"defence": "theta20", "byzantines": 8})
    assert c.payment.params["theta"] == 20.0 and [g.count for g in c.swarm.groups] == [17, 8]
    with pytest.raises(ConfigError, match="matches 0 conditions"):
        select_cell(exp, {"defence": "nonsense"})


def test_an_experiment_without_attackers_is_refused():
    with pytest.raises(ConfigError, match="no robot runs `attacker`"):
        Runs(load_experiment("fig2A").with_overrides(steps=10), 1)


@pytest.mark.parametrize("actions", [("theta",), ("nope",), ("rot_base", "rot_base"), ()])
def test_actions_must_be_policy_parameters_once(cfg, actions):
    with pytest.raises(ConfigError, match="policy parameters"):
        Runs(cfg, 1, actions=actions)


def test_chain_runs_are_simulate_bit_for_bit(cfg):
    # the RL interface runs the engine's own driver, so a chain run is a run like any other
    chain = cfg.with_overrides(steps=400, chain={"consensus": "poa", "period": 10, "out_of_turn_delay": 5})
    runs = Runs(chain, 2)
    play(runs, SEEDS[:2], 50)
    for b, seed in enumerate(SEEDS[:2]):
        ref = simulate(chain, seed)
        np.testing.assert_array_equal(runs.worlds[b].balance, ref.robots.wealth.to_numpy())
        assert int(runs.worlds[b].chn_blocks[0]) == ref.totals["chain"]["blocks"] > 0


def test_the_vector_runs_step_on_the_kernels_own_entry_and_compile_no_second_one(cfg):
    # the kernel's code is compiled once, into its step_all, whether runs go alone or through the RL
    # interface (whose observation is a call of its own): a driver linking the kernel would compile again
    from numba.core import event

    simulate(cfg.with_overrides(steps=300, transitory=100), SEEDS[0])  # this process has the kernel now
    compiled = []

    class Compiles(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            compiled.append(ev.data["dispatcher"].py_func.__name__)

    listener = Compiles()
    event.register("numba:compile", listener)
    try:
        runs = Runs(cfg, 2)
        play(runs, SEEDS[:2], 3)
    finally:
        event.unregister("numba:compile", listener)
    assert not [m for m in sys.modules if m.startswith("infomarket_batch")]  # no driver module of its own
    assert "step_all" not in compiled, compiled
    assert runs.sims.kernel.__name__.startswith("infomarket_kernel_")
