"""Fixed-point encodings shared by the contract and its Python clients.

The simulator works in floats; the contract only has integers. Every quantity crosses the boundary
through one of these functions, so the encoding is decided in one place:

- token amounts: integer units of 1e-9 token (``TOKEN_UNIT``). The paper's amounts (wealth 1, reward 1,
  share 0.5, stake 0.04) are exact in it, and it is coarse enough that the simulator's float error
  (about 1e-13 after thousands of operations) stays far below one unit, so "equal up to the unit"
  is a meaningful comparison between the two ledgers;
- information share: a WAD (1e18 = the whole reward);
- directions: integer microdegrees in [0, 360e6), for display and for the simulated ledger only; the
  contract never sees a direction, it compares vectors;
- positions and vectors: signed integer micro arena units (int64), enough for any vector a robot can
  hold. Rounding a 10-unit vector to micro units turns it by under 1e-7 rad, so it can only change an
  outlier-similarity decision when two directions differ by Theta within about 6e-6 degrees;
- cos(Theta): integer units of 1e-9 (``COS_SCALE``).
"""
from __future__ import annotations

from decimal import Decimal

from .errors import UnitsError

TOKEN_UNIT = 10**9
WAD = 10**18
MICRO = 10**6
FULL_TURN = 360 * MICRO
COS_SCALE = 10**9
_INT64 = 2**63


def _exact(value: float) -> Decimal:
    """The decimal the user wrote (``repr``), so that 0.04 becomes exactly 4e7 units, not 4e7 + dust."""
    return Decimal(repr(float(value)))


def to_units(amount: float) -> int:
    """Token amount -> integer ledger units (nearest)."""
    return int((_exact(amount) * TOKEN_UNIT).to_integral_value())


def from_units(units: int) -> float:
    """Integer ledger units -> token amount."""
    return units / TOKEN_UNIT


def share_to_wad(share: float) -> int:
    """Information share in [0, 1] -> WAD."""
    return int((_exact(share) * WAD).to_integral_value())


def to_microdegrees(degrees: float) -> int:
    """Direction in degrees (any real) -> microdegrees in [0, 360e6)."""
    return int((_exact(degrees) * MICRO).to_integral_value()) % FULL_TURN


def to_micro(coordinate: float) -> int:
    """Position coordinate -> signed micro units; refuses what does not fit the contract's int64."""
    value = int((_exact(coordinate) * MICRO).to_integral_value())
    if not -_INT64 <= value < _INT64:
        raise UnitsError(f"coordinate {coordinate} does not fit in int64 micro units")
    return value
