"""The optimiser both trainings of an attack policy take (``rl.train``'s evolution strategies and the
adaptive-attack search, ``search.adaptive``): Adam, in numpy, on whatever array of parameters it is given.

It lives apart from either training so that the attack search does not depend on the RL layer.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Adam:
    """Adam (Kingma & Ba 2015) ascending a gradient estimate."""

    lr: float
    beta1: float = 0.9
    beta2: float = 0.999
    eps: float = 1e-8
    t: int = 0
    m: np.ndarray | None = None
    v: np.ndarray | None = None

    def step(self, grad: np.ndarray) -> np.ndarray:
        """The Adam step for gradient ``grad`` (bias-corrected moments); the caller applies it to the parameters."""
        if self.m is None or self.v is None:
            self.m, self.v = np.zeros_like(grad), np.zeros_like(grad)
        self.t += 1
        self.m = self.beta1 * self.m + (1 - self.beta1) * grad
        self.v = self.beta2 * self.v + (1 - self.beta2) * grad * grad
        mh = self.m / (1 - self.beta1 ** self.t)
        vh = self.v / (1 - self.beta2 ** self.t)
        return self.lr * mh / (np.sqrt(vh) + self.eps)
