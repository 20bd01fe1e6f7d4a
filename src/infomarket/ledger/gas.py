"""The contract's measured gas as the chain model charges it (docs/gas.md, docs/chain-model.md): a reveal's
gas and a deposit's gas by the number of reveals it settles, per payment scheme, and the one rule that
reads the deposit table (the compiled model and the chain demo's model figure share it)."""
from __future__ import annotations

from numba import njit

#: Gas of one ``revealInformation`` call, the mean over a round trip of 16 reveals (docs/gas.md,
#: "reveal, mean", n = 16): delayed payment, outlier penalisation, outlier penalisation with staking.
GAS_REVEAL_DELAYED = 90_155
GAS_REVEAL_OUTLIER = 90_156
GAS_REVEAL_STAKING = 94_038
#: Gas of a deposit (``buyItem`` and the ``settle`` calls) by the number n of reveals it settles
#: (docs/gas.md, "deposit, later trips": the steady state of a running swarm).
GAS_DEPOSIT_N = (1, 4, 16, 64, 256, 1024)
GAS_DEPOSIT_DELAYED = (109_864, 118_638, 153_784, 374_383, 1_171_407, 4_359_503)
GAS_DEPOSIT_OUTLIER = (114_496, 135_168, 320_151, 3_444_418, 53_184_194, 1_064_925_378)
GAS_DEPOSIT_STAKING = (114_496, 135_168, 320_151, 3_424_518, 53_164_294, 1_064_905_478)


def gas_schedule(scheme: str, stake: float) -> tuple[float, tuple[int, ...]]:
    """(reveal gas, deposit gas by n) for a payment scheme: the delayed scheme's figures for ``delayed``,
    the outlier scheme's (with staking when ``stake > 0``) for every other scheme."""
    if scheme == "delayed":
        return float(GAS_REVEAL_DELAYED), GAS_DEPOSIT_DELAYED
    if stake > 0:
        return float(GAS_REVEAL_STAKING), GAS_DEPOSIT_STAKING
    return float(GAS_REVEAL_OUTLIER), GAS_DEPOSIT_OUTLIER


@njit
def table_gas(xs, ys, n):
    """Gas of a deposit that settles n reveals by the table (xs reveals, ys gas): linear between its points
    and beyond its last two; n below the first point costs the first point's gas.  Also the chain demo's
    model figure (chain.block_replay), so both read one rule."""
    m = xs.shape[0]
    if n <= xs[0]:
        return ys[0]
    k = 1
    while k < m - 1 and n > xs[k]:
        k += 1
    return ys[k - 1] + (ys[k] - ys[k - 1]) * (n - xs[k - 1]) / (xs[k] - xs[k - 1])
