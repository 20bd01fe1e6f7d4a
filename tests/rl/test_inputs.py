"""The RL interface refuses what it cannot take, naming the argument (an InfomarketError), before writing
anything into a run: None, text, NaN and wrong shapes as actions, a cell that is not a dict, actions given
as one string, an empty experiment name, a vector env too large for memory, a step before reset, and a
parallel step that leaves agents without an action."""
import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from infomarket.config import sizes
from infomarket.errors import ArgumentError, InfomarketError, InputTypeError, UsageError
from infomarket.rl import AttackEnv, AttackParallelEnv, AttackVectorEnv
from infomarket.rl.envs import configured

SMALL = dict(steps=60, transitory=20, interval=10)


@pytest.fixture(scope="module")
def env():
    return AttackEnv(**SMALL)


def _params(e) -> np.ndarray:
    """The agents' action parameters as the run holds them now (run 0)."""
    return e.runs.bparams[0][e.runs.agents][:, e.runs.columns].copy()


@pytest.mark.parametrize("action, error, words", [
    (None, InputTypeError, "action is None"),
    ("abc", InputTypeError, "not an array of numbers"),
    ([[1, 2], [3, "x"], [5, 6]], InputTypeError, "not an array of numbers"),
    (5.0, ArgumentError, "shape ()"),
    (np.zeros((2, 7)), ArgumentError, "shape (2, 7)"),
    (np.zeros(2), ArgumentError, "shape (2,)"),
    (np.array([[np.nan, 0.0], [0.0, 0.0], [0.0, 0.0]]), ArgumentError, "NaN at (0, 0)"),
])
def test_a_step_refuses_an_action_it_cannot_apply_and_leaves_the_run_as_it_was(env, action, error, words):
    env.reset(seed=0)
    before, clock = _params(env), env.runs.clocks.copy()
    with pytest.raises(error) as info:
        env.step(action)
    assert words in str(info.value)
    assert np.array_equal(_params(env), before) and np.array_equal(env.runs.clocks, clock)


def test_infinite_actions_are_clipped_to_the_parameter_range_like_any_other(env):
    env.reset(seed=0)
    env.step(np.array([[np.inf, -np.inf]] * 3))
    assert np.array_equal(_params(env), np.array([[180.0, 0.0]] * 3))  # rot_base in [0, 180], collude in [0, 1]


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(cell="staking"), InputTypeError, "cell='staking'"),
    (dict(cell=["staking", 3]), InputTypeError, "cell=['staking', 3]"),
    (dict(actions="rot_base"), InputTypeError, "actions='rot_base'"),
    (dict(actions=5), InputTypeError, "actions=5"),
])
def test_the_constructors_refuse_arguments_of_the_wrong_kind(kwargs, error, words):
    for cls in (AttackEnv, AttackParallelEnv):
        with pytest.raises(error) as info:
            cls(**SMALL, **kwargs)
        assert words in str(info.value)


@pytest.mark.parametrize("name", ["", "   "])
def test_an_empty_experiment_name_is_refused_naming_it(name):
    with pytest.raises(InfomarketError, match="experiment") as info:
        AttackEnv(name, **SMALL)
    assert "directory" not in str(info.value)


def test_a_vector_env_too_large_for_memory_is_refused_before_any_world_is_built(monkeypatch):
    import infomarket.rl.envs

    monkeypatch.setenv(sizes.ENV, "16GiB")
    monkeypatch.setattr(infomarket.rl.envs, "Runs", lambda *a, **k: pytest.fail("built the runs"))
    with pytest.raises(ArgumentError, match=r"num_envs=10000000: 10,000,000 runs at once would need about"):
        AttackVectorEnv(num_envs=10**7, **SMALL)


def test_the_vector_env_needs_reset_before_step_and_actions_of_its_shape():
    v = AttackVectorEnv(num_envs=2, **SMALL)
    act = np.zeros(v.action_space.shape, np.float32)
    with pytest.raises(UsageError, match="reset"):
        v.step(act)
    v.reset(seed=0)
    with pytest.raises(ArgumentError, match=r"shape \(3, 3, 3\); this environment takes shape \(2, 3, 2\)"):
        v.step(np.zeros((3, 3, 3)))
    bad = act.copy()
    bad[1, 2, 1] = np.nan
    with pytest.raises(ArgumentError, match=r"NaN at \(1, 2, 1\)"):
        v.step(bad)
    with pytest.raises(InputTypeError, match="None"):
        v.step(None)
    obs, *_ = v.step(act)  # and a good action still steps
    assert obs.shape == v.observation_space.shape


def test_a_parallel_step_needs_an_action_for_every_acting_agent():
    p = AttackParallelEnv(**SMALL)
    p.reset(seed=0)
    for actions, error, words in (({}, UsageError, "no action for robot_22, robot_23, robot_24"),
                                  ({"robot_22": np.zeros(2)}, UsageError, "no action for robot_23, robot_24"),
                                  ([np.zeros(2)] * 3, InputTypeError, "a dict"),
                                  ({a: np.zeros(5) for a in p.agents}, ArgumentError, "shape (5,)"),
                                  ({a: np.array([np.nan, 0.0]) for a in p.agents}, ArgumentError, "NaN")):
        with pytest.raises(error) as info:
            p.step(actions)
        assert words in str(info.value)
    assert p.runs.clocks[0] == 0  # nothing was stepped
    p.step({a: np.zeros(2) for a in p.agents})
    assert p.runs.clocks[0] == SMALL["interval"]


def test_the_distinct_defence_is_a_cell_of_the_environments():
    # what every environment runs for a cell (``envs.configured``), without compiling a kernel for it
    cfg = configured("attack_search", {"defence": "distinct", "byzantines": 3}, SMALL["steps"], SMALL["transitory"])
    assert cfg.payment.scheme == "outlier_distinct"
    assert cfg.steps == SMALL["steps"] and sum(g.count for g in cfg.swarm.groups if g.behaviour == "attacker") == 3
