"""Error bits set by compiled code (which cannot raise) and turned into exceptions by the host."""
from enum import IntFlag


class ErrorFlags(IntFlag):
    """Bits of ``World.flags[0]``."""

    TX_OVERFLOW = 1  #: a buy rule made more purchases in one step than the per-step reserve allows
    BAD_WEIGHTS = 2  #: a payment rule returned a negative or non-finite weight
    EVENT_OVERFLOW = 4  #: the event log reserve was exceeded within one step

    def describe(self) -> str:
        """The raised flags in words, joined by "; " (what the engine's error message says went wrong).

        Example:
            >>> from infomarket.state.flags import ErrorFlags
            >>> ErrorFlags.BAD_WEIGHTS.describe()
            'a payment rule returned a negative or non-finite weight'
        """
        text = {
            ErrorFlags.TX_OVERFLOW: "a buy rule made more than 2 purchases per neighbour in one step",
            ErrorFlags.BAD_WEIGHTS: "a payment rule returned a negative or non-finite weight",
            ErrorFlags.EVENT_OVERFLOW: "more events or payments in one step than their logs reserve",
        }
        return "; ".join(msg for bit, msg in text.items() if bit in self)


# Plain ints for use inside compiled code.
TX_OVERFLOW = int(ErrorFlags.TX_OVERFLOW)
BAD_WEIGHTS = int(ErrorFlags.BAD_WEIGHTS)
EVENT_OVERFLOW = int(ErrorFlags.EVENT_OVERFLOW)
