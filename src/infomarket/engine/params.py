"""The run's parameters: everything the step reads and nothing changes (the arena, the robots' physics,
sampling tables, sites and obstacles, the rules' parameters), and their builder.

Read-only in compiled code for everyone (``state.view``): a rule that writes one does not compile.  The
market's terms (reward, shares, stake, the scheme's parameters) are the ledger's (``ledger.state``), and
the log's settings (``record``, ``hist_every``) the log's (``state.log``).
"""
from __future__ import annotations

import math

import numpy as np
from ..jit import njit

from ..config.schema import Experiment
from ..registry import behaviours
from ..space import obstacles
from ..space.grid import grid_shape
from ..state.spec import Spec, fields
from .geometry import DEG

# Sites: a robot's table, spots and states have one entry per kind of site.
FOOD = 0
NEST = 1
SITE_NAMES = ("food", "nest")

SPEC = Spec("params", fields("host", [
    ("width", "float", "", "arena width"),
    ("height", "float", "", "arena height"),
    ("radius", "float", "", "robot radius"),
    ("speed", "float", "", "distance a robot moves per step"),
    ("comm_range", "float", "", "robots strictly closer than this communicate"),
    ("noise_sd", "float", "", "standard deviation of the odometry's turning noise, degrees"),
    ("fuel_cost", "float", "", "money a robot burns per move (0: none)"),
    ("transitory", "int", "", "items count from this step on"),
    ("stop_time", "int", "", "steps both robots stop after a trade"),
    ("cooldown", "int", "", "further steps in which neither trades again"),
    ("sites_xy", "float64", "S,2", "site centres: food sites first, then nests, in file order (one of each "
                                   "on the paper's plane: site index = FOOD / NEST)"),
    ("sites_r", "float64", "S", "site radii"),
    ("sites_kind", "int64", "S", "FOOD / NEST"),
    ("obs_kind", "int64", "K", "obstacle shapes (space.obstacles)"),
    ("obs_geom", "float64", "K,4", "obstacle geometry (space.obstacles)"),
    ("line_of_sight", "bool", "", "an obstacle between two robots cuts their link"),
    ("collisions", "bool", "", "a move that would overlap another robot is not made"),
    ("sense_robots", "bool", "", "proximity sensors also fire for other robots"),
    ("cauchy_cdf", "float64", "360", "turn-angle CDF of the random walk (whole degrees)"),
    ("cauchy_guide", "int64", "360", "guide table: O(1) sampling of cauchy_cdf (guide_table)"),
    ("levy_cdf", "float64", "steps+1", "step-length CDF of the random walk"),
    ("levy_guide", "int64", "steps+1", "guide table of levy_cdf"),
    ("turn_cos", "float64", "360", "cos of each whole-degree turn (the kernel's libm)"),
    ("turn_sin", "float64", "360", "sin of each whole-degree turn"),
    ("bparams", "float64", "n,B", "each robot's behaviour parameters, in its behaviour's declared order"),
    ("grid_cell", "float", "", "side of a neighbour-grid cell (>= comm_range)"),
    ("grid_nx", "int", "", "grid cells across"),
    ("grid_ny", "int", "", "grid cells down"),
]))


def cauchy_cdf(rho: float) -> np.ndarray:
    """CDF of the wrapped Cauchy turning angle (eq. 2) on whole degrees 0..359."""
    phi = np.arange(360) * math.pi / 180.0
    f = (1 - rho**2) / (2 * math.pi * (1 + rho**2 - 2 * rho * np.cos(phi)))
    cdf = np.cumsum(f / f.sum())
    cdf[-1] = 1.0
    return cdf


#: Entries of the guide table computed at once: its construction holds no second table-sized array.
GUIDE_CHUNK = 1 << 20


def levy_cdf(alpha: float, steps: int) -> np.ndarray:
    """CDF of Lévy step lengths (eq. 3), P(k) ∝ k^-(alpha+1) for k = 1..steps+1 (index k-1).  Computed in
    place (the same values as ``cumsum(k ** -(alpha+1) / sum)``): the table is 8 bytes per step of the run."""
    p = np.arange(1, steps + 2, dtype=np.float64)
    p **= -(alpha + 1.0)
    p /= p.sum()
    cdf = np.cumsum(p, out=p)
    cdf[-1] = 1.0
    return cdf


def guide_table(cdf: np.ndarray) -> np.ndarray:
    """For u in [j/M, (j+1)/M): the answer of inverse-CDF sampling is at least ``guide[j]`` (M = len(cdf)),
    the first index whose cumulative probability exceeds j/M (computed in chunks of ``GUIDE_CHUNK``)."""
    m = len(cdf)
    guide = np.empty(m, np.int64)
    for a in range(0, m, GUIDE_CHUNK):
        b = min(m, a + GUIDE_CHUNK)
        guide[a:b] = np.searchsorted(cdf, np.arange(a, b, dtype=np.float64) / m, side="right")
    return guide


def turn_tables() -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of every whole-degree turn, computed by compiled code (the libm calls compiled code
    makes), so a turn costs the kernel a table read instead of two calls."""
    c = np.empty(360)
    s = np.empty(360)
    fill_turn_tables(c, s, DEG)
    return c, s


@njit(cache=True)
def fill_turn_tables(cos_out, sin_out, deg):
    """cos and sin of every whole-degree turn (``turn_tables``), with compiled code's libm."""
    for k in range(cos_out.shape[0]):
        a = float(k) * deg
        cos_out[k] = math.cos(a)
        sin_out[k] = math.sin(a)


def site_arrays(cfg: Experiment) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every site as (centres [S, 2], radii [S], kinds [S]): food sites first, then nests, file order."""
    sites = [(s, FOOD) for s in cfg.sites("food")] + [(s, NEST) for s in cfg.sites("nest")]
    return (np.array([[s.x, s.y] for s, _ in sites], dtype=np.float64),
            np.array([s.radius for s, _ in sites], dtype=np.float64),
            np.array([k for _, k in sites], dtype=np.int64))


def behaviour_kinds(cfg: Experiment) -> tuple[str, ...]:
    """Distinct behaviours in order of first appearance: a robot's ``kind`` indexes this tuple."""
    names: list[str] = []
    for g in cfg.swarm.groups:
        if g.count and g.behaviour not in names:
            names.append(g.behaviour)
    return tuple(names)


def behaviour_table(cfg: Experiment, kinds: tuple[str, ...] | None = None) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Robots in group order (ids follow the groups): each one's kind (an index into ``kinds``, by default
    ``behaviour_kinds(cfg)``), its parameter row, its name."""
    n = cfg.swarm.robots
    kinds = behaviour_kinds(cfg) if kinds is None else kinds
    specs = behaviours()
    n_par = max([len(specs[b].params) for b in kinds] + [1])
    kind = np.empty(n, np.int64)
    bparams = np.zeros((n, n_par))
    names: list[str] = []
    start = 0
    for g in cfg.swarm.groups:
        if g.count == 0:
            continue
        kind[start:start + g.count] = kinds.index(g.behaviour)
        values = list(cfg.behaviour_params(g).values())
        bparams[start:start + g.count, :len(values)] = values
        names += [g.behaviour] * g.count
        start += g.count
    return kind, bparams, names


def build_params(cfg: Experiment, bparams: np.ndarray) -> dict:
    """The parameters of a run of ``cfg`` (``bparams`` from ``behaviour_table``)."""
    r = cfg.robot.radius
    rc = float(cfg.robot.communication_range)
    cell, nx, ny = grid_shape(float(cfg.arena.width), float(cfg.arena.height), rc, cfg.swarm.robots)
    cauchy = cauchy_cdf(cfg.random_walk.rho)
    levy = levy_cdf(cfg.random_walk.alpha, cfg.steps)
    turn_cos, turn_sin = turn_tables()
    sites_xy, sites_r, sites_kind = site_arrays(cfg)
    obs_kind, obs_geom = obstacles.encode(cfg.obstacles)
    params = {
        "width": float(cfg.arena.width), "height": float(cfg.arena.height), "radius": float(r),
        "speed": float(cfg.robot.speed), "comm_range": rc, "noise_sd": float(cfg.robot.noise_sd),
        "fuel_cost": float(cfg.robot.fuel_cost), "transitory": int(cfg.transitory),
        "stop_time": int(cfg.robot.stop_time), "cooldown": int(cfg.robot.cooldown),
        "sites_xy": sites_xy, "sites_r": sites_r, "sites_kind": sites_kind, "obs_kind": obs_kind,
        "obs_geom": obs_geom, "line_of_sight": bool(cfg.robot.line_of_sight),
        "collisions": bool(cfg.robot.collisions), "sense_robots": bool(cfg.robot.sense_robots),
        "cauchy_cdf": cauchy, "cauchy_guide": guide_table(cauchy), "levy_cdf": levy, "levy_guide": guide_table(levy),
        "turn_cos": turn_cos, "turn_sin": turn_sin, "bparams": bparams,
        "grid_cell": cell, "grid_nx": nx, "grid_ny": ny,
    }
    SPEC.check(params)
    return params
