"""Age-aware fusion with an innovation gate: the robotics answer to "how much should I believe this?".

An honest vector is wrong by the odometry drift of everyone who dead-reckoned it, so its error grows
with its age (bias × age), and so does the error of the robot's own entry.  The paper's weighting
(eqs. 4-5) uses ages but accepts any vector; the sceptic checks vectors but ignores ages.  The
``gated_fusion`` buyer gives each vector a variance from its age and length, rejects an offer whose
innovation (its distance from the own entry) is improbable under both variances (a chi-square gate),
and fuses the rest Kalman-style (docs/defences.md).

Written through the public API alone; registered as ``gated_fusion`` by ``infomarket.builtins``.
"""
import math

from ..jit import njit

from .api import buy, current, install, next_younger


@njit(forceinline=True, cache=True)
def age_variance(x, y, age, drift, floor):
    """Expected squared error of a vector (x, y) dead-reckoned for ``age`` steps: ``floor`` ** 2 (where in
    the site the vector points) plus the squared arc a rotation of ``drift`` degrees per step sweeps
    at its length, ``(|v| * age * drift * pi / 180) ** 2``."""
    arc = math.sqrt(x * x + y * y) * age * drift * math.pi / 180.0
    return floor * floor + arc * arc


@njit(forceinline=True, cache=True)
def gate_and_fuse(ox, oy, p_own, x, y, p_offer, gate):
    """The innovation test and the Kalman update of a 2-d position with isotropic errors: the squared
    Mahalanobis distance ``d2 = 2 |v - o| ** 2 / (p_own + p_offer)`` (each component has half the expected
    squared error) is chi-square with 2 degrees of freedom for honest vectors.  Returns (accepted, fused x,
    fused y, gain): rejected when ``d2 > gate``, else ``o + K (v - o)`` with ``K = p_own / (p_own + p_offer)``."""
    s = p_own + p_offer
    dx = x - ox
    dy = y - oy
    if s <= 0.0:
        return dx == 0.0 and dy == 0.0, ox, oy, 0.5
    d2 = 2.0 * (dx * dx + dy * dy) / s
    if d2 > gate:
        return False, ox, oy, 0.0
    k = p_own / s
    return True, ox + k * dx, oy + k * dy, k


def gated_fusion_buy(w, me, nbrs, drift=0.1, floor=10.0, gate=9.21):
    """Per site, candidates in (offered age, id) order, younger than the current entry: buy; an invalid
    entry takes the purchase (nothing to gate against); otherwise the purchase is fused with the entry
    (``gate_and_fuse``, variances from ``age_variance``) or, past the ``gate`` (9.21: 99 % of honest
    innovations under the model), rejected, and the next candidate is tried.  One accepted purchase per
    site per step, as the naive robot; the fused age is the gain-weighted mean of the two ages, floored."""
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            valid, ox, oy, oage = current(w, me, site)
            ok, x, y, age = buy(w, me, s, site)
            if not ok:
                continue
            if not valid:
                install(w, me, site, x, y, age)
                break
            accepted, fx, fy, k = gate_and_fuse(ox, oy, age_variance(ox, oy, oage, drift, floor),
                                                x, y, age_variance(x, y, age, drift, floor), gate)
            if accepted:
                install(w, me, site, fx, fy, int(math.floor((1.0 - k) * oage + k * age)))
                break
