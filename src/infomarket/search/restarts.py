"""The searchers' points: start points spread over the cube, CMA-ES restarted from them, and random search.

The global search spends a share of its budget (``spread``) on start points spread over the whole cube
(``design``: a scrambled Sobol sequence seeded from the study's seed and the cell), so it does not only
refine the strongest known attack: a weakness far from every hand-written attack is sampled as densely
as a random search would, and the restarts then refine the best of what was sampled.  ``Restarts`` runs
CMA-ES (``cma``) restart after restart, the population doubled at each (IPOP): a small population
refines, a large one explores; each restart gets an equal share of the rest of the budget, and its
population is capped so it still makes at least ``MIN_GENERATIONS`` generations.  ``random_batches`` is
the baseline every search must beat: uniform points, in batches of one population, as many as the
global search evaluates (start points included).

Everything here is a pure function of the settings and seeds: ``cma`` samples from NumPy's global
generator, which is reseeded before every ``ask`` from (study seed, cell, restart, generation), so a
search that starts again replays exactly the points it asked before.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from . import refine
from .structured import per_round
from .study import Settings

#: the fewest generations a restart's population is capped to allow (when its share of the budget allows)
MIN_GENERATIONS = 3


def stream(*parts) -> int:
    """A stable integer for ``parts`` (a seed stream, or a generator's seed)."""
    text = "/".join(map(str, parts))
    return int(hashlib.sha256(text.encode()).hexdigest()[:15], 16)


def design(n: int, dim: int, seed: int) -> np.ndarray:
    """``n`` points spread over [0, 1]^dim: a scrambled Sobol sequence (its first ``n`` points)."""
    from scipy.stats import qmc  # scipy.stats is slow to import: only when a search starts

    sobol = qmc.Sobol(dim, scramble=True, seed=np.random.default_rng(seed))
    m = max(0, int(np.ceil(np.log2(max(n, 1)))))
    return sobol.random_base2(m)[:n]


@dataclass(frozen=True)
class Leg:
    """One restart: its population and number of generations."""

    popsize: int
    generations: int

    @property
    def evaluations(self) -> int:
        """The evaluations this restart spends (population x generations)."""
        return self.popsize * self.generations


def spread_points(s: Settings) -> int:
    """How many start points the design spreads over the cube: ``spread`` of the budget, one per restart at least."""
    return min(s.budget, max(s.restarts, round(s.spread * s.budget)))


def gate_points(s: Settings) -> int:
    """Evaluations of the structured start (``search.structured``): its rounds' openings, within the budget."""
    return min(s.gate_rounds * per_round(), max(0, s.budget - spread_points(s)))


def refine_points(s: Settings) -> int:
    """Evaluations kept for the last phase's moves (``search.refine``): its rounds' points at most, within the
    budget."""
    return min(s.refine * refine.per_round(), max(0, s.budget - spread_points(s) - gate_points(s)))


def plan(s: Settings) -> list[Leg]:
    """The restarts' populations and generations: equal shares of the budget left after the start points
    and the structured start (what a restart cannot use goes to the next), the population doubled per
    restart and capped at share / ``MIN_GENERATIONS``."""
    legs, spent = [], 0
    budget = s.budget - spread_points(s) - gate_points(s) - refine_points(s)
    for r in range(s.restarts):
        share = budget * (r + 1) // s.restarts - spent
        pop = max(2, min(s.popsize * 2 ** r, max(s.popsize, share // MIN_GENERATIONS)))
        gens = share // pop
        if gens == 0:
            continue
        legs.append(Leg(pop, gens))
        spent += pop * gens
    return legs


def evaluations(s: Settings) -> int:
    """Candidate evaluations of the global search, start points, openings and the refinement's moves included
    (and of the random search)."""
    return spread_points(s) + gate_points(s) + refine_points(s) + sum(leg.evaluations for leg in plan(s))


class Restarts:
    """CMA-ES restarted per ``plan``: ``ask()`` gives (restart, generation, points) or None when the
    budget is spent; ``tell(fitness)`` the values of the points last asked.  Restart ``r`` starts at
    ``start(r)``, called when the restart begins (so it may depend on what was found before); the first
    ``s.local`` restarts step ``s.local_sigma`` (local refinements), the others ``s.sigma0``."""

    def __init__(self, s: Settings, dim: int, seed: int, start):
        self.s, self.dim, self.seed, self.start = s, dim, seed, start
        self.legs = plan(s)
        self.r, self.g, self.es, self.asked = 0, 0, None, None

    def _open(self) -> None:
        import cma  # the optimiser's library: only when a search runs

        leg = self.legs[self.r]
        x0 = np.clip(np.asarray(self.start(self.r), float), 0.0, 1.0)
        opts = {"bounds": [0.0, 1.0], "popsize": leg.popsize,
                "seed": stream(self.seed, "cma", self.r) % (2**31 - 2) + 1,
                "verbose": -9, "verb_log": 0, "verb_disp": 0, "verb_filenameprefix": "", "tolfun": 0.0,
                "tolx": 0.0, "tolfunhist": 0.0, "tolstagnation": 10**9, "tolflatfitness": 10**9}
        sigma = self.s.local_sigma if self.r < self.s.local else self.s.sigma0
        self.es = cma.CMAEvolutionStrategy(x0, sigma, opts)

    def ask(self) -> tuple[int, int, np.ndarray] | None:
        """The next points to evaluate, as (restart, generation, points in [0, 1]^dim); None once the budget is
        spent."""
        if self.r >= len(self.legs):
            return None
        if self.es is None:
            self._open()
        np.random.seed(stream(self.seed, "cma", self.r, "gen", self.g) % (2**32))  # what cma samples from
        self.asked = np.asarray(self.es.ask(), float)
        return self.r, self.g, self.asked

    def tell(self, fitness) -> None:
        """Hand back the fitness of the points last asked; moves to the next generation, or restart."""
        self.es.tell(list(self.asked), list(map(float, fitness)))
        self.g += 1
        if self.g >= self.legs[self.r].generations:
            self.r, self.g, self.es = self.r + 1, 0, None


def random_batches(s: Settings, dim: int, seed: int) -> list[np.ndarray]:
    """The random search: uniform points in [0, 1]^dim, batches of ``popsize``, ``evaluations(s)`` in all."""
    total, out, g = evaluations(s), [], 0
    while total > 0:
        n = min(s.popsize, total)
        out.append(np.random.default_rng(stream(seed, "random", g)).random((n, dim)))
        total, g = total - n, g + 1
    return out
