"""The rotation grid: constant liars from 0° to 180°, alone or colluding, about each site, as baselines
every search must beat beside the declared hand-written attacks.

The hand-written attacks cover small rotations and gated policies; the grid covers the whole range of the
one parameter every attack has, so a search that "wins" only where no hand-written attack looked (large
rotations) is measured against the plain attack there too.  The grid is generated, not declared: its
names say what each point is, ``rot_030_collude_nest`` = a 30° lie about the nest only (``lie_site`` 1,
see ``behaviours.attacks.POLICY``), colluding; ``rot_120_solo_both`` = a 120° lie about both sites, alone.
Every point is a point of the search space (``search.space``), so it runs in the same kernel.
"""
from __future__ import annotations

import numpy as np

#: ``lie_site`` values and the name each takes in a baseline's label
SITES = {0.0: "food", 1.0: "nest", 2.0: "both"}
PREFIX = "rot_"


def angles(step: float) -> list[float]:
    """0°, step, 2 step ... up to 180° (180° included even when ``step`` does not divide it)."""
    out = [float(a) for a in np.arange(0.0, 180.0, step)]
    return out + [180.0]


def name(rotation: float, collude: bool, site: float) -> str:
    """The label of one grid point: its rotation, whether it colludes, and the site it lies about.

    Example:
        >>> from infomarket.search.baselines import name
        >>> name(30.0, True, 1.0), name(22.5, False, 2.0)
        ('rot_030_collude_nest', 'rot_022p500_solo_both')
    """
    whole = int(round(rotation))
    deg = f"{whole:03d}" if abs(rotation - whole) < 1e-9 else f"{rotation:07.3f}".replace(".", "p")
    return f"{PREFIX}{deg}_{'collude' if collude else 'solo'}_{SITES[float(site)]}"


def rotation_grid(step: float) -> dict[str, dict[str, float]]:
    """Every grid baseline, by name: the rotation, collusion and lie_site set, every other gate off."""
    out = {}
    for rotation in angles(step):
        for collude in (False, True):
            for site in SITES:
                out[name(rotation, collude, site)] = {"rot_base": rotation, "collude": float(collude),
                                                      "lie_site": site}
    return out
