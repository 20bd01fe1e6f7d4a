"""The Gymnasium and PettingZoo environments: their own API checkers, rewards against simulate(), the
vector env against the single one, and next-step autoreset."""
import warnings

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test, parallel_seed_test

from infomarket.config import load_experiment
from infomarket.engine.simulation import simulate
from infomarket.errors import UsageError
from infomarket.rl import AttackEnv, AttackParallelEnv, AttackVectorEnv

SMALL = dict(steps=300, transitory=100, interval=10)


def test_gymnasium_check_env_passes_with_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(AttackEnv(**SMALL), skip_render_check=True)


def test_pettingzoo_parallel_api_test_passes():
    env = AttackParallelEnv(**SMALL)
    parallel_api_test(env, num_cycles=40)  # 40 decisions > 30 per episode: the end is crossed
    assert env.possible_agents == ["robot_22", "robot_23", "robot_24"]  # the 3 `attacker` robots of 25


def test_pettingzoo_parallel_seed_test_passes():
    parallel_seed_test(lambda: AttackParallelEnv(**SMALL), num_cycles=10)


def _episode(env, action):
    obs, info = env.reset(seed=4)
    total, done = 0.0, False
    while not done:
        obs, r, term, trunc, info = env.step(action)
        total += r
        assert not term
        done = trunc
    return total, info["seed"]


def test_the_items_return_is_minus_the_runs_honest_items_per_honest_robot():
    env = AttackEnv(steps=1500, transitory=300, interval=10)
    total, seed = _episode(env, env.runs.default_action)
    ref = simulate(load_experiment("attack_search").with_overrides(steps=1500, transitory=300), seed).robots
    honest = ref[ref.honest].items_collected
    assert honest.sum() > 0  # items were collected in this run
    assert total == pytest.approx(-honest.sum() / len(honest))


def test_the_liar_wealth_return_is_the_byzantines_gain_in_wealth_share():
    env = AttackEnv(steps=1500, transitory=300, interval=10, reward="liar_wealth")
    total, seed = _episode(env, env.runs.default_action)
    ref = simulate(load_experiment("attack_search").with_overrides(steps=1500, transitory=300), seed).robots
    start = 3 / 25  # every robot starts with the same wealth
    assert total == pytest.approx(ref[~ref.honest].wealth_share.sum() - start)
    assert total != pytest.approx(0.0)


def test_parallel_rewards_are_each_agents_own_share_gain():
    env = AttackParallelEnv(steps=1500, transitory=300, interval=10, reward="liar_wealth")
    obs, infos = env.reset(seed=4)
    totals = dict.fromkeys(env.possible_agents, 0.0)
    while env.agents:
        act = {a: np.array([20.0, 0.0], np.float32) for a in env.agents}
        obs, rewards, term, trunc, infos = env.step(act)
        for a, r in rewards.items():
            totals[a] += r
    ref = simulate(load_experiment("attack_search").with_overrides(steps=1500, transitory=300),
                   infos["robot_22"]["seed"]).robots
    for a in env.possible_agents:
        assert totals[a] == pytest.approx(ref.wealth_share[int(a.split("_")[1])] - 1 / 25)


def test_sub_environment_i_is_the_single_env_seeded_with_seed_plus_i():
    venv = AttackVectorEnv(num_envs=3, **SMALL)
    single = AttackEnv(**SMALL)
    acts = [venv.action_space.sample() for _ in range(30)]
    vobs, vinfo = venv.reset(seed=10)
    vrew = []
    for a in acts:
        vobs_t, r, term, trunc, vinfo = venv.step(a)
        vrew.append(r)
    vrew = np.array(vrew)
    assert trunc.all() and not term.any()
    for i in range(3):
        obs, info = single.reset(seed=10 + i)
        rews = [single.step(a[i])[1] for a in acts]
        np.testing.assert_allclose(vrew[:, i], rews)
        assert info["seed"] == vinfo["seed"][i]


def test_next_step_autoreset_starts_a_fresh_episode_and_ignores_the_action():
    venv = AttackVectorEnv(num_envs=2, steps=300, transitory=10, interval=100, reward="liar_wealth")
    venv.reset(seed=1)
    for _ in range(3):
        obs, r, term, trunc, info = venv.step(venv.action_space.sample())
    assert trunc.all() and (venv.runs.clocks == 300).all()
    ended = venv.runs.shares.sum(axis=1)
    assert (ended != 3 / 25).all()  # the episodes moved wealth: a fresh run's shares differ from them
    first = info["seed"].copy()
    obs, r, term, trunc, info = venv.step(venv.action_space.sample())
    assert (venv.runs.clocks == 0).all() and (r == 0).all() and not trunc.any()
    assert (info["seed"] != first).all()
    assert (obs[:, :, 6] == 0).all()  # the time column of a fresh run
    obs, r, term, trunc, info = venv.step(venv.action_space.sample())
    assert (venv.runs.clocks == 100).all()


def test_the_same_seed_gives_the_same_episode():
    venv = AttackVectorEnv(num_envs=2, **SMALL)
    a = np.broadcast_to(np.array([35.0, 0.0], np.float32), venv.action_space.shape)
    out = []
    for _ in range(2):
        obs, _ = venv.reset(seed=7)
        for _ in range(12):
            obs, r, *_ = venv.step(a)
        out.append((obs, venv.runs.worlds[0].balance.copy()))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    np.testing.assert_array_equal(out[0][1], out[1][1])


def test_stepping_an_ended_episode_is_refused():
    env = AttackEnv(steps=20, transitory=5, interval=10)
    with pytest.raises(UsageError, match="reset"):
        env.step(env.action_space.sample())
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.step(env.action_space.sample())
    with pytest.raises(UsageError, match="reset"):
        env.step(env.action_space.sample())
