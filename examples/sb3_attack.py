"""Train Stable-Baselines3's PPO on ``AttackEnv``: one controller for the Byzantine robots (docs/rl.md).

Needs the ``sb3`` extra (``pip install 'infomarket[sb3]'``: stable-baselines3 and torch).  The env comes
from Gymnasium's registry (``import infomarket.rl`` registers it); PPO's Gaussian policy acts in
[-1, 1], so ``RescaleAction`` maps that onto each parameter's own range; ``FlattenObservation`` gives
its network one row of every agent's observation.  Then the learned policy and the experiment's constant
20-degree liar play the same held-out seeds, and the script prints the honest robots' items per honest
robot under each (lower: the stronger attack).

    python examples/sb3_attack.py --timesteps 20000
"""
from __future__ import annotations

import argparse
import json

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import FlattenObservation, RescaleAction
from stable_baselines3 import PPO

import infomarket.rl  # registers infomarket/Attack-v0 with Gymnasium

#: Evaluation seeds start here, away from the training episodes' seeds (drawn from the training seed).
HELD_OUT = 10_000


def make_env(args) -> gym.Env:
    env = gym.make(infomarket.rl.ENV_ID, steps=args.steps, transitory=args.transitory, interval=args.interval)
    ones = np.ones(env.action_space.shape, np.float32)
    return FlattenObservation(RescaleAction(env, min_action=-ones, max_action=ones))


def play(env: gym.Env, policy, seed: int) -> tuple[float, int]:
    """One episode from ``reset(seed=seed)``: its return (minus honest items per honest robot) and the
    run's seed (``simulate(config, seed=...)`` replays it)."""
    obs, info = env.reset(seed=seed)
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        done = terminated or truncated
    return total, int(info["seed"])


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=20_000, help="PPO's training decisions")
    parser.add_argument("--steps", type=int, default=4000, help="engine steps per episode")
    parser.add_argument("--transitory", type=int, default=1000, help="steps before items count")
    parser.add_argument("--interval", type=int, default=20, help="engine steps per decision (K)")
    parser.add_argument("--eval-runs", type=int, default=16, help="held-out seeds each policy plays")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    env = make_env(args)
    model = PPO("MlpPolicy", env, n_steps=min(256, args.timesteps), batch_size=64, seed=args.seed, device="cpu",
                verbose=0)
    model.learn(total_timesteps=args.timesteps)

    liar = env.unwrapped.runs.default_action  # the experiment's own attack, in the env's units
    low, high = env.unwrapped.action_space.low, env.unwrapped.action_space.high
    liar_scaled = 2.0 * (liar - low) / (high - low) - 1.0  # the same attack in the wrapper's [-1, 1]
    seeds = range(HELD_OUT + args.seed * args.eval_runs, HELD_OUT + (args.seed + 1) * args.eval_runs)
    learned = [play(env, lambda obs: model.predict(obs, deterministic=True)[0], s) for s in seeds]
    constant = [play(env, lambda obs: liar_scaled, s) for s in seeds]
    result = {
        "timesteps": int(model.num_timesteps),
        "run_seeds": [s for _, s in constant],
        "learned_items_per_honest": [-r for r, _ in learned],
        "liar_items_per_honest": [-r for r, _ in constant],
    }
    result["mean_learned"] = float(np.mean(result["learned_items_per_honest"]))
    result["mean_liar"] = float(np.mean(result["liar_items_per_honest"]))
    print(json.dumps({k: v for k, v in result.items() if k.startswith(("mean", "time"))}))
    return result


if __name__ == "__main__":
    main()
