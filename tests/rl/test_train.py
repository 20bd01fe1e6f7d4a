"""rl.train: the ES estimate ascends a function whose optimum is known, and training on a tiny attack
setting is deterministic and improves the attack it starts from."""
import numpy as np
import pytest

from infomarket.agents.optim import Adam
from infomarket.rl.train import centred_ranks, es_gradient, initial_theta, sigmoid


def test_centred_ranks_by_hand():
    np.testing.assert_allclose(centred_ranks(np.array([3.0, -1.0, 10.0, 0.0])), [1 / 6, -0.5, 0.5, -1 / 6])


def test_es_with_adam_climbs_to_the_optimum_of_a_quadratic():
    target = np.array([[1.5, -2.0], [0.5, 3.0]])
    rng = np.random.default_rng(0)
    theta, opt = np.zeros_like(target), Adam(0.1)
    for _ in range(300):
        eps = rng.standard_normal((8,) + theta.shape)
        cands = np.repeat(theta[None], 16, axis=0)
        cands[0::2] += 0.2 * eps
        cands[1::2] -= 0.2 * eps
        fitness = -((cands - target) ** 2).sum(axis=(1, 2))
        theta = theta + opt.step(es_gradient(fitness, eps, 0.2))
    np.testing.assert_allclose(theta, target, atol=0.15)


def test_the_antithetic_estimate_points_along_the_better_perturbation():
    eps = np.array([[1.0, 0.0], [0.0, 1.0]])
    # pair 0: +eps better; pair 1: -eps better -> ranks [+0.5, -1/6, -0.5, 1/6] (fitness 9, 1, -5, 2)
    g = es_gradient(np.array([9.0, 1.0, -5.0, 2.0]), eps, 0.5)
    np.testing.assert_allclose(g, [(0.5 + 1 / 6) / 1.0, (-0.5 - 1 / 6) / 1.0])


class _Runs:  # what initial_theta reads of agents.runs.Runs
    actions = ("rot_base", "collude")
    low, high = np.array([0.0, 0.0]), np.array([180.0, 1.0])
    default_action = np.array([[20.0, 0.0]] * 3)
    obs = np.zeros((1, 3, 19))


def test_the_policy_starts_at_the_configured_attack():
    theta = initial_theta(_Runs)
    assert theta.shape == (20, 2) and not theta[:-1].any()
    assert 180 * sigmoid(theta[-1, 0]) == pytest.approx(20.0)  # the constant 20° liar
    assert sigmoid(theta[-1, 1]) == pytest.approx(0.01)  # collude: at the edge margin, below 0.5 (off)


def test_tiny_training_is_deterministic_and_improves_on_the_constant_liar():
    pytest.importorskip("gymnasium")
    from infomarket.rl.envs import AttackVectorEnv
    from infomarket.rl.run import compare
    from infomarket.rl.train import train

    env = AttackVectorEnv(num_envs=8, steps=2000, transitory=500, interval=10)
    a = train(env, iterations=4, pairs=4, seed=3)
    b = train(env, iterations=4, pairs=4, seed=3)
    np.testing.assert_array_equal(a.theta, b.theta)
    assert a.fitness == b.fitness
    r = compare(env, a, 16, seed=3)
    assert r["learned_mean"] < r["liar_mean"]  # fewer honest items on the same held-out seeds


def test_ascending_the_return_does_more_damage_than_descending_it(monkeypatch):
    """The direction of the update matters: the same loop made to descend its return (the ES estimate
    negated) ends at an attack that leaves the honest robots more items than the ascending one.  At 5
    iterations ES is noisy (of training seeds 3-6, 3 separate this way), so one seed is used."""
    pytest.importorskip("gymnasium")
    from infomarket.rl import train as train_mod
    from infomarket.rl.envs import AttackVectorEnv
    from infomarket.rl.run import held_out_seeds

    env = AttackVectorEnv(num_envs=16, steps=4000, transitory=1000, interval=10)
    up = train_mod.train(env, iterations=5, pairs=8, seed=3)
    ascend = train_mod.es_gradient
    monkeypatch.setattr(train_mod, "es_gradient", lambda f, e, s: -ascend(f, e, s))
    down = train_mod.train(env, iterations=5, pairs=8, seed=3)
    seeds = held_out_seeds(3, 16)
    _, items_up = train_mod.episodes(env, np.repeat(up.theta[None], 16, axis=0), seeds)
    _, items_down = train_mod.episodes(env, np.repeat(down.theta[None], 16, axis=0), seeds)
    assert items_up.mean() < items_down.mean()
