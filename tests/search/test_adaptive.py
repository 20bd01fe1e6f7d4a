"""search.adaptive: the adaptive attacker's policy plays what a parametric attacker plays, confirm() gives
the per-run values of ordinary runs on the given seeds, training is deterministic, resumes to the same
policy, and improves on its start against a planted weak defence (and does not when its update is
reversed)."""
import numpy as np
import pandas as pd
import pytest

from infomarket.config import load_experiment
from infomarket.config.load import validate
from infomarket.engine.simulation import simulate
from infomarket.errors import ArgumentError, UsageError
from infomarket.agents.observe import OBSERVATION
from infomarket.search import adaptive, study
from infomarket.search.adaptive import Policy, centred_ranks, confirm, es_gradient, train
from infomarket.search.objective import per_run
from infomarket.search.study import Cell

SHORT = {"steps": 1500, "transitory": 500}


@pytest.fixture(scope="module")
def staking():
    return study.cells(study.load(load_experiment("attack_search")), ["staking"], [3])[0]


@pytest.fixture(scope="module")
def weak(staking):
    """A planted weak defence: sceptics that accept any rotation and an outlier threshold of 180°, so the
    truthful start leaves the honest robots far more items than a wide lie does."""
    d = staking.config.model_dump()
    for g in (0, 1):
        d["swarm"]["groups"][g]["params"]["threshold"] = 2.0
    d["payment"]["params"] = {**d["payment"].get("params", {}), "theta": 180.0}
    d["swarm"]["groups"][1]["params"]["theta"] = 180.0
    return Cell("weak", 3, validate(d, "weak"))


def reference(cell, params, seeds, steps, transitory):
    """Per-run values of ordinary runs (``simulate``) of the cell with the attacker's ``params``."""
    cfg = cell.with_attack(params, steps=steps, transitory=transitory)
    robots = pd.concat([simulate(cfg, s).robots.assign(experiment=cfg.name, condition="c", run=k)
                        for k, s in enumerate(seeds)], ignore_index=True)
    return per_run(robots)[["run", "items", "liar_wealth"]]


# ----------------------------------------------------------------------------------------- pieces
def test_centred_ranks_average_ties_by_hand():
    # values 3, 1, 3, 0: ranks 0 -> 0, 1 -> 1, the two 3s share (2 + 3) / 2; scaled by 1/3, minus 0.5
    np.testing.assert_allclose(centred_ranks(np.array([3.0, 1.0, 3.0, 0.0])), [1 / 3, -1 / 6, 1 / 3, -0.5])


def test_identical_candidates_give_no_update():
    eps = np.random.default_rng(0).standard_normal((4, 3))
    np.testing.assert_array_equal(es_gradient(np.full(8, 2.5), eps, 0.1), 0.0)


def test_the_antithetic_estimate_points_along_the_better_perturbation():
    eps = np.array([[1.0, 0.0], [0.0, 1.0]])
    # pair 0: +eps better; pair 1: -eps better: ranks of (9, 1, -5, 2) are 3, 1, 0, 2 -> 1/2, -1/6, -1/2, 1/6
    np.testing.assert_allclose(es_gradient(np.array([9.0, 1.0, -5.0, 2.0]), eps, 0.5),
                               [(0.5 + 1 / 6) / 1.0, (-0.5 - 1 / 6) / 1.0])


def test_a_constant_policy_plays_its_values_and_a_linear_one_reads_the_observation():
    p = Policy.constant({"rot_base": 45.0, "collude": 1.0})
    obs = np.random.default_rng(1).random((3, len(OBSERVATION)))
    np.testing.assert_allclose(p.act(obs), [[45.0, 1.0]] * 3)
    w = np.zeros((len(OBSERVATION) + 1, 2))
    w[OBSERVATION.index("theta"), 0] = 0.8  # the Θ-surfer: 0.8 x the Θ applied (observed as Θ / 180)
    surfer = Policy(w)
    obs = np.zeros(len(OBSERVATION))
    obs[OBSERVATION.index("theta")] = 30.0 / 180.0
    np.testing.assert_allclose(surfer.act(obs), [24.0, 0.0])
    w[-1, 0] = 2.0  # clipped at the range's top
    assert Policy(w).act(obs)[0] == 180.0


def test_a_policy_saves_and_loads_exactly(tmp_path):
    w = np.random.default_rng(2).standard_normal((len(OBSERVATION) + 1, 3))
    p = Policy(w, ("rot_base", "collude", "lie_site"), 7, {"max_confirmers": 2.0}, {"note": "x"})
    q = Policy.load(p.save(tmp_path / "p.npz"))
    np.testing.assert_array_equal(q.weights, p.weights)
    assert (q.actions, q.interval, q.base, q.info) == (p.actions, 7, {"max_confirmers": 2.0}, {"note": "x"})
    (tmp_path / "bad.npz").write_text("not a policy")
    with pytest.raises(UsageError, match="not an adaptive attacker's policy"):
        Policy.load(tmp_path / "bad.npz")


@pytest.mark.parametrize("kwargs, words", [({"actions": "rot_base"}, "a sequence"), ({"actions": ("nope",)}, "one of"),
                                           ({"interval": 0}, "interval"), ({"base": {"x": 1}}, "unknown")])
def test_bad_policies_are_refused(kwargs, words):
    with pytest.raises(ArgumentError, match=words):
        Policy(np.zeros((len(OBSERVATION) + 1, 1 if "actions" in kwargs else 2)), **kwargs)


# ----------------------------------------------------------------------------------------- confirm
def test_a_constant_policy_is_the_parametric_attacker_run_for_run(staking):
    seeds = [11, 2024, 987654321]
    for values in ({"rot_base": 37.5, "collude": 1.0}, {"rot_base": 0.0, "collude": 0.0}):
        p = Policy.constant(values)
        got = confirm(staking, p, seeds, **SHORT)
        want = reference(staking, p.at_rest(), seeds, **SHORT)  # the values the policy plays, as parameters
        assert list(got.columns) == ["attack", "run", "items", "liar_wealth"] and (got.attack == "adaptive").all()
        pd.testing.assert_frame_equal(got[["run", "items", "liar_wealth"]], want, check_exact=True)
    liar = confirm(staking, Policy.constant({"rot_base": 37.5, "collude": 1.0}), seeds, **SHORT)
    assert not np.array_equal(liar.liar_wealth, got.liar_wealth)  # the actions change the runs


def test_confirm_of_an_adaptive_policy_is_the_vector_env_episode_and_independent_of_batching(staking):
    gym = pytest.importorskip("gymnasium")
    from infomarket.rl.envs import AttackVectorEnv

    w = np.zeros((len(OBSERVATION) + 1, 2))
    w[OBSERVATION.index("food_buyers"), 0] = 20.0  # the truth alone, a wide lie with buyers around
    w[OBSERVATION.index("nest_buyers"), 0] = 20.0
    w[OBSERVATION.index("nest_sellers"), 1] = 20.0  # colludes with other sellers around
    w[-1] = [-0.2, 0.0]
    p = Policy(w)
    env = AttackVectorEnv(staking.with_attack({}, **SHORT), 3, interval=p.interval)
    obs, info = env.reset(seed=5)
    truncated = np.zeros(3, bool)
    while not truncated.all():
        obs, _, _, truncated, _ = env.step(p.act(obs))
    cfg = env.runs.config
    played = per_run(pd.concat([sim.result().robots.assign(experiment=cfg.name, condition="c", run=k)
                                for k, sim in enumerate(env.runs.sims.sims)], ignore_index=True))
    seeds = [int(s) for s in info["seed"]]
    got = confirm(staking, p, seeds, **SHORT)
    np.testing.assert_array_equal(got["items"], env.runs.items / len(env.runs.honest))
    pd.testing.assert_frame_equal(got[["run", "items", "liar_wealth"]], played[["run", "items", "liar_wealth"]],
                                  check_exact=True)
    np.testing.assert_array_equal(confirm(staking, p, seeds, batch=2, **SHORT), got)
    constant = confirm(staking, Policy.constant({"rot_base": 0.0}), seeds, **SHORT)
    assert not np.array_equal(constant.liar_wealth, got.liar_wealth)
    assert gym  # the env is Gymnasium's


# ----------------------------------------------------------------------------------------- training
TINY = dict(pairs=2, runs=1, steps=1000, transitory=0, sigma=0.2, lr=0.1)


def test_training_is_deterministic_for_a_seed(staking):
    a = train(staking, 10, seed=4, **TINY)
    b = train(staking, 10, seed=4, **TINY)
    c = train(staking, 10, seed=5, **TINY)
    np.testing.assert_array_equal(a.weights, b.weights)
    assert a.info == b.info and a.info["generations"] == 2
    assert not np.array_equal(a.weights, c.weights)


def test_workers_and_batches_change_no_result(staking):
    one = train(staking, 10, seed=4, **TINY)
    pooled = train(staking, 10, seed=4, workers=2, batch=2, **TINY)
    np.testing.assert_array_equal(pooled.weights, one.weights)
    assert pooled.info == one.info
    seeds = [3, 4, 5]
    pd.testing.assert_frame_equal(confirm(staking, one, seeds, workers=2, batch=1, **SHORT),
                                  confirm(staking, one, seeds, **SHORT), check_exact=True)


def test_a_resumed_training_gives_the_same_policy_and_repeats_no_run(staking, tmp_path):
    whole = train(staking, 15, seed=4, **TINY)

    class Stop(Exception):
        pass

    def stop_after_first(g, record):
        if g == 0:
            raise Stop

    with pytest.raises(Stop):
        train(staking, 15, seed=4, checkpoint=tmp_path, on_generation=stop_after_first, **TINY)
    assert adaptive.resumed_generations(tmp_path) == 1
    played = []
    resumed = train(staking, 15, seed=4, checkpoint=tmp_path, on_runs=played.append, **TINY)
    np.testing.assert_array_equal(resumed.weights, whole.weights)
    assert resumed.info == whole.info
    assert sum(played) == 2 * 5 * 1  # generations 1 and 2 only, 5 candidates of 1 run each
    with pytest.raises(UsageError, match="a checkpoint of another training"):
        train(staking, 15, seed=5, checkpoint=tmp_path, **TINY)


def test_training_beats_its_start_against_a_planted_weak_defence(weak, monkeypatch):
    """From the truth (rotation 0), ES finds lies that cost the honest robots items on fresh seeds; the
    same loop with its update reversed does not."""
    setup = dict(pairs=4, runs=2, steps=3000, transitory=1000, seed=1, sigma=0.1, lr=0.05,
                 start={"rot_base": 0.0, "collude": 0.0})
    up = train(weak, 8 * 9, **setup)
    ascend = adaptive.es_gradient
    monkeypatch.setattr(adaptive, "es_gradient", lambda f, e, s: -ascend(f, e, s))
    down = train(weak, 8 * 9, **setup)
    seeds = list(range(900, 916))
    start = confirm(weak, Policy.constant(setup["start"]), seeds, steps=3000, transitory=1000)["items"]
    learned = confirm(weak, up, seeds, steps=3000, transitory=1000)["items"]
    reversed_ = confirm(weak, down, seeds, steps=3000, transitory=1000)["items"]
    assert learned.mean() < start.mean() - 0.3  # far more than the runs' standard error (about 0.1)
    assert learned.mean() < reversed_.mean() - 0.3, (start.mean(), learned.mean(), reversed_.mean())


def test_bad_training_arguments_are_refused_before_any_run(staking, monkeypatch):
    monkeypatch.setattr(adaptive, "Player", None)  # any run would fail on this
    for kwargs, words in (({"pairs": 0}, "pairs"), ({"sigma": float("nan")}, "sigma"),
                          ({"objective": "gold"}, "objective"), ({"actions": ("theta_x",)}, "one of")):
        with pytest.raises(ArgumentError, match=words):
            train(staking, 10, **kwargs)


def test_the_declared_comparison_picks_on_selection_seeds_and_scores_on_fresh_ones(staking):
    from infomarket.search import adaptive_compare

    hand = {"liar10": {"rot_base": 10.0}, "liar90": {"rot_base": 90.0}}
    p = Policy.constant({"rot_base": 40.0})
    r = adaptive_compare.compare(staking, p, hand, {"lie_from_rep": 1.0}, selection=3, confirmation=4, **SHORT)
    sel = adaptive_compare.seeds_of(staking, "selection", 3)
    conf = adaptive_compare.seeds_of(staking, "confirmation", 4)
    assert not set(sel) & set(conf)
    means = {n: reference(staking, q, sel, **SHORT)["items"].mean() for n, q in hand.items()}
    assert r["selection_means"] == pytest.approx(means, abs=1e-12)
    assert r["best_hand_written"] == min(means, key=means.get)
    np.testing.assert_array_equal(r["learned"], reference(staking, p.at_rest(), conf, **SHORT)["items"])
    np.testing.assert_array_equal(r["hand_written"],
                                  reference(staking, hand[r["best_hand_written"]], conf, **SHORT)["items"])
    assert r["answer"] in ("yes", "no", "inconclusive")
