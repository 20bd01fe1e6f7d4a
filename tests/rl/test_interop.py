"""The environments in the ecosystem: Gymnasium's registry (make, make_vec), its checker with the render
check, rendering the arena, PettingZoo's API test with a render mode, SuperSuit's vector wrapper, and
pickled or copied environments that play exactly as the original."""
import copy
import pickle
import warnings

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env  # noqa: E402 - after the skip without the rl extra
from pettingzoo.test import parallel_api_test  # noqa: E402 - after the skip without the rl extra

from infomarket.errors import ConfigError, UsageError  # noqa: E402 - after the skip without the rl extra
from infomarket.rl import ENV_ID, AttackEnv, AttackParallelEnv, AttackVectorEnv  # noqa: E402 - after the skip without the rl extra
from infomarket.viewer import movie  # noqa: E402 - after the skip without the rl extra

SMALL = dict(steps=300, transitory=100, interval=10)


def test_gymnasium_make_builds_the_attack_env_with_the_given_arguments():
    env = gym.make(ENV_ID, **SMALL, reward="liar_wealth")
    assert ENV_ID == "infomarket/Attack-v0" and env.spec.id == ENV_ID
    inner = env.unwrapped
    assert type(inner) is AttackEnv
    assert (inner.runs.steps, inner.interval, inner.reward_name) == (300, 10, "liar_wealth")


def test_gymnasium_make_vec_builds_the_compiled_vector_env():
    venv = gym.make_vec(ENV_ID, num_envs=3, **SMALL)
    assert type(venv) is AttackVectorEnv  # one compiled call for the 3 runs, not 3 envs in a SyncVectorEnv
    obs, info = venv.reset(seed=0)
    assert obs.shape == (3, 3, 19) and venv.runs.steps == 300


def test_gymnasium_check_env_passes_with_its_render_check_and_no_warning():
    env = gym.make(ENV_ID, **SMALL, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)  # with env.spec: it also makes one env per declared render mode


def _orange_near(img, x, y, scale, top, reach=3):
    """Pixels of the movie's Byzantine fill within ``reach`` pixels of world point (x, y)."""
    cx, cy = round(x * scale), round(top + y * scale)
    patch = img[cy - reach:cy + reach + 1, cx - reach:cx + reach + 1].astype(int)
    return int(np.all(np.abs(patch - (0xE6, 0x9F, 0x00)) < 40, axis=-1).sum())


def test_render_draws_the_arena_as_the_movie_does_with_the_robots_where_they_are():
    env = AttackEnv(**SMALL, render_mode="rgb_array")
    env.reset(seed=1)
    for _ in range(5):
        env.step(env.runs.default_action)
    img = env.render()
    width = 720  # rl.interop.RENDER_WIDTH_PX; attack_search's arena is 1200 x 600
    assert img.dtype == np.uint8 and img.shape == (40 + 26 + 360 + 28, width, 3)
    scale, top = width / 1200, 40 + 26  # caption and legend above the arena
    w = env.runs.worlds[0]
    for i in range(25):
        near = _orange_near(img, w.pos[i, 0], w.pos[i, 1], scale, top)
        if i in (22, 23, 24):  # the attackers: an orange disc where each one is
            assert near > 4, (i, near)
    honest_blue = np.all(np.abs(img.astype(int) - (0x00, 0x72, 0xB2)) < 40, axis=-1).sum()
    assert honest_blue > 22 * 10
    env.step(env.runs.default_action)
    assert not np.array_equal(env.render(), img)  # the robots moved


def test_render_without_a_render_mode_is_none_and_an_unknown_mode_is_refused():
    assert AttackEnv(**SMALL).render() is None
    with pytest.raises(ConfigError, match="render_mode 'human'.*'rgb_array'"):
        AttackEnv(**SMALL, render_mode="human")


def test_the_vector_env_renders_each_sub_environment():
    venv = AttackVectorEnv(num_envs=2, **SMALL, render_mode="rgb_array")
    venv.reset(seed=3)
    a, b = venv.render()
    assert a.shape == b.shape == (454, 720, 3) and not np.array_equal(a, b)  # two runs, two seeds


def test_pettingzoo_parallel_api_test_passes_with_a_render_mode():
    env = AttackParallelEnv(**SMALL, render_mode="rgb_array")
    assert env.render_mode == "rgb_array"
    parallel_api_test(env, num_cycles=40)
    env.reset(seed=0)
    assert env.render().shape == (454, 720, 3)


def test_supersuit_wraps_the_parallel_env_as_a_vector_env():
    ss = pytest.importorskip("supersuit")
    env = AttackParallelEnv(**SMALL, render_mode="rgb_array")
    venv = ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(env), 2, num_cpus=0, base_class="gymnasium")
    try:
        obs, info = venv.reset(seed=0)
        assert obs.shape == (2 * 3, 19)  # 2 copies of the env x 3 agents, one row each
        act = np.tile(np.array([20.0, 0.0], np.float32), (6, 1))
        obs, rew, term, trunc, info = venv.step(act)
        assert obs.shape == (6, 19) and rew.shape == (6,) and not term.any() and not trunc.any()
    finally:
        venv.close()


def _play(env, seed, actions):
    obs, info = env.reset(seed=seed)
    out = [(obs, info["seed"] if isinstance(info, dict) and "seed" in info else info)]
    for a in actions:
        out.append(env.step(a)[:2])
    return out


def _same(a, b):
    for x, y in zip(a, b, strict=True):
        for u, v in zip(x, y, strict=True):
            np.testing.assert_array_equal(np.asarray(u), np.asarray(v))


@pytest.mark.parametrize("dup", [lambda e: pickle.loads(pickle.dumps(e)), copy.deepcopy], ids=["pickle", "deepcopy"])
def test_a_copied_env_plays_as_the_original(dup):
    env = AttackEnv(**SMALL)
    acts = [env.action_space.sample() for _ in range(12)]
    _play(env, 5, acts[:4])  # the original is mid-episode when copied
    twin = dup(env)
    assert type(twin) is AttackEnv and twin.runs is not env.runs
    _same(_play(env, 9, acts), _play(twin, 9, acts))
    with pytest.raises(UsageError, match="reset"):
        dup(env).step(acts[0])  # a copy starts before its first reset


def test_a_copy_continues_the_originals_random_stream():
    env = AttackEnv(**SMALL)
    env.reset(seed=2)
    twin = copy.deepcopy(env)
    fresh = AttackEnv(**SMALL)
    seeds = [e.reset()[1]["seed"] for e in (env, twin, fresh)]
    assert seeds[0] == seeds[1] != seeds[2]


def test_a_pickled_env_is_its_arguments_not_its_worlds():
    env = AttackEnv(**SMALL)
    env.reset(seed=0)
    assert len(pickle.dumps(env)) < 5_000  # the 25 robots' arrays alone are larger


def test_the_vector_and_parallel_envs_pickle_and_play_as_the_original():
    venv = AttackVectorEnv(num_envs=2, **SMALL)
    acts = [venv.action_space.sample() for _ in range(8)]
    _same(_play(venv, 4, acts), _play(pickle.loads(pickle.dumps(venv)), 4, acts))
    par = AttackParallelEnv(**SMALL)
    twin = copy.deepcopy(par)
    assert twin.render_mode is None and twin.possible_agents == par.possible_agents
    a = {agent: np.array([30.0, 1.0], np.float32) for agent in par.possible_agents}
    o1, _ = par.reset(seed=6)
    o2, _ = twin.reset(seed=6)
    for _ in range(5):
        r1, r2 = par.step(a), twin.step(a)
        for k in range(2):
            for agent in par.possible_agents:
                np.testing.assert_array_equal(r1[k][agent], r2[k][agent])


def test_an_env_sent_to_worker_processes_plays_as_the_original():
    """Gymnasium's AsyncVectorEnv with fresh worker processes ("spawn": nothing inherited) pickles each
    env function to its worker: here the function returns an env built in this process, so the env
    itself crosses by pickling and is rebuilt there."""
    env = AttackEnv(**SMALL)
    acts = [np.stack([env.action_space.sample()] * 2) for _ in range(6)]
    venv = gym.vector.AsyncVectorEnv([lambda e=env: e, lambda e=env: e], context="spawn")
    try:
        obs, info = venv.reset(seed=[11, 11])
        far = [venv.step(a)[:2] for a in acts]
    finally:
        venv.close()
    near = _play(env, 11, [a[0] for a in acts])
    np.testing.assert_array_equal(obs[0], near[0][0])
    np.testing.assert_array_equal(obs[1], near[0][0])
    for (o, r), (o1, r1) in zip(far, near[1:], strict=True):
        np.testing.assert_array_equal(o[0], o1)
        assert r[0] == r1 and r[1] == r1


def test_the_movie_picture_draws_an_rl_frame_with_its_episode_seed():
    env = AttackEnv(**SMALL, render_mode="rgb_array")
    env.reset(seed=0)
    env.render()
    assert isinstance(env._renderer.picture, movie.ArenaPicture)
    assert f"seed {env.runs.seeds[0]}:" in env._renderer.picture.caption.get_text()
