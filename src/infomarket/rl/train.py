"""A short training example: evolution strategies (numpy) over a linear policy shared by the Byzantine
robots, through the vector environment, learning an attack that does more damage than the constant 20°
liar it starts from (docs/rl.md has the command, the declared comparison and the measured result).

Policy: each agent's action column c is ``low_c + (high_c - low_c) * sigmoid(obs . W[:, c] + b_c)``,
``theta = [W; b]`` ([len(OBSERVATION) + 1, len(actions)]), the same for every agent; it starts at the
experiment's own attack (W = 0, b at the configured parameters: the constant 20° liar of attack_search).

Evolution strategies (Salimans et al. 2017, "Evolution Strategies as a Scalable Alternative to
Reinforcement Learning"): per iteration, ``pairs`` Gaussian perturbations of theta, each tried as +eps and
-eps on the same run seed (antithetic sampling with common random numbers), every candidate one
sub-environment of one ``AttackVectorEnv`` (so a whole population runs in one compiled call per decision
interval); the fitness is the episode's return, turned into centred ranks; theta moves along
``sum(rank(+eps) - rank(-eps)) * eps / (pairs * sigma)`` with Adam.  Same seed -> the same theta.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..agents.optim import Adam
from ..errors import ArgumentError
from ..seeds import MAX_SEED

#: A logit never further from 0 than this when the policy is started at a parameter on its range's edge.
EDGE = 0.01


def sigmoid(x):
    """The logistic function, mapping the policy's outputs into (0, 1) before they are scaled to the action bounds."""
    return 1.0 / (1.0 + np.exp(-x))


def initial_theta(runs) -> np.ndarray:
    """The policy that plays the experiment's own attack parameters (W = 0, b their logits)."""
    u = (runs.default_action.mean(axis=0) - runs.low) / (runs.high - runs.low)
    u = np.clip(u, EDGE, 1.0 - EDGE)
    theta = np.zeros((runs.obs.shape[2] + 1, len(runs.actions)))
    theta[-1] = np.log(u / (1.0 - u))
    return theta


def actions(runs, thetas: np.ndarray, obs: np.ndarray) -> np.ndarray:
    """Each run b's agents' actions under its policy ``thetas[b]``: [B, agents, len(actions)]."""
    z = np.einsum("bao,bok->bak", obs, thetas[:, :-1]) + thetas[:, None, -1]
    return runs.low + (runs.high - runs.low) * sigmoid(z)


def centred_ranks(x: np.ndarray) -> np.ndarray:
    """Ranks scaled to [-0.5, 0.5] (ties keep their order of appearance)."""
    r = np.empty(len(x))
    r[np.argsort(x, kind="stable")] = np.arange(len(x))
    return r / max(len(x) - 1, 1) - 0.5


def es_gradient(fitness: np.ndarray, eps: np.ndarray, sigma: float) -> np.ndarray:
    """The antithetic ES estimate of the fitness gradient: ``fitness`` [2 * pairs] holds each pair's +eps
    and -eps candidates side by side, ``eps`` [pairs, ...] the perturbations."""
    u = centred_ranks(fitness)
    diff = u[0::2] - u[1::2]
    return np.tensordot(diff, eps, axes=1) / (len(eps) * sigma)


def episodes(env, thetas: np.ndarray | None, seeds, fixed: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Play one episode per (policy, seed) (policy ``thetas[i]``, or the ``fixed`` action when given) in
    chunks of the vector env's size; returns (returns, honest items per honest robot)."""
    runs, n, b = env.runs, len(seeds), env.num_envs
    calls = -(-runs.steps // env.interval)
    ret, items = np.zeros(n), np.zeros(n)
    for start in range(0, n, b):
        idx = np.arange(start, start + b) % n  # the last chunk is padded with repeats, then dropped
        obs, _ = env.reset(seed=[int(seeds[i]) for i in idx])
        total = np.zeros(b)
        for _ in range(calls):
            if fixed is not None:
                act = np.broadcast_to(fixed, obs.shape[:2] + fixed.shape[-1:])
            else:
                assert thetas is not None, "episodes: thetas or fixed"
                act = actions(runs, thetas[idx], obs)
            obs, r, _, _, _ = env.step(act.astype(np.float32))
            total += r
        keep = slice(0, min(b, n - start))
        ret[start:start + b][keep] = total[keep]
        items[start:start + b][keep] = (runs.items / max(len(runs.honest), 1))[keep]
    return ret, items


@dataclass
class Training:
    """What ``train`` produced: the final policy, the fitness of each iteration's population (mean) and
    of the policy at each iteration's start (the mean of the +eps / -eps pairs is an estimate of it)."""

    theta: np.ndarray
    start: np.ndarray
    fitness: list[float] = field(default_factory=list)


def train(env, *, iterations: int, pairs: int, sigma: float = 0.5, lr: float = 0.2, seed: int = 0,
          on_iteration=None) -> Training:
    """Evolution strategies on ``env`` (an ``AttackVectorEnv`` with ``2 * pairs`` sub-environments)."""
    if env.num_envs != 2 * pairs:
        raise ArgumentError(f"the vector env must hold 2 x pairs = {2 * pairs} runs, has {env.num_envs}")
    rng = np.random.default_rng(seed)
    theta = initial_theta(env.runs)
    out = Training(theta.copy(), theta.copy())
    opt = Adam(lr)
    for it in range(iterations):
        eps = rng.standard_normal((pairs,) + theta.shape)
        cands = np.repeat(theta[None], 2 * pairs, axis=0)
        cands[0::2] += sigma * eps
        cands[1::2] -= sigma * eps
        seeds = np.repeat(rng.integers(0, MAX_SEED, pairs, endpoint=True), 2)
        fit, _ = episodes(env, cands, seeds)
        theta = theta + opt.step(es_gradient(fit, eps, sigma))
        out.fitness.append(float(fit.mean()))
        if on_iteration is not None:
            on_iteration(it, float(fit.mean()))
    out.theta = theta
    return out
