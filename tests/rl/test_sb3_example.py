"""examples/sb3_attack.py: Stable-Baselines3's PPO trains on AttackEnv from Gymnasium's registry, and its
evaluation scores the runs the engine makes.  Needs the sb3 extra (torch): skipped without it."""
import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from infomarket.config import load_experiment
from infomarket.engine.simulation import simulate

EXAMPLE = Path(__file__).parents[2] / "examples" / "sb3_attack.py"
ARGS = ["--timesteps", "128", "--steps", "1500", "--transitory", "300", "--interval", "30", "--eval-runs", "2"]


@pytest.fixture(scope="module")
def example():
    spec = importlib.util.spec_from_file_location("sb3_attack", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ppo_trains_and_the_liars_score_is_the_engines_run(example):
    out = example.main(ARGS + ["--seed", "0"])
    assert out["timesteps"] == 128
    cfg = load_experiment("attack_search").with_overrides(steps=1500, transitory=300)
    for seed, score in zip(out["run_seeds"], out["liar_items_per_honest"], strict=True):
        robots = simulate(cfg, seed).robots  # the constant liar is the experiment's own attack
        honest = robots[robots.honest].items_collected
        assert score == pytest.approx(honest.sum() / len(honest))
    assert sum(out["liar_items_per_honest"]) > 0  # items were collected: the comparison means something
    assert len(out["learned_items_per_honest"]) == 2 and all(x >= 0 for x in out["learned_items_per_honest"])


def test_the_same_seed_learns_the_same_policy(example):
    a, b = (example.main(ARGS + ["--seed", "1"]) for _ in range(2))
    assert a["learned_items_per_honest"] == b["learned_items_per_honest"] and a["run_seeds"] == b["run_seeds"]


def test_stable_baselines3s_own_checker_passes_on_the_examples_env(example):
    import argparse
    import warnings

    from stable_baselines3.common.env_checker import check_env

    env = example.make_env(argparse.Namespace(steps=300, transitory=100, interval=10))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)
