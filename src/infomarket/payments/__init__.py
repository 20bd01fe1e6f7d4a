"""Payment schemes: weight rules over a buyer's open transactions (registered by ``infomarket.builtins``
through the public ``register_payment``)."""
from ..registry import get_payment

#: The paper's stake (docs/model.md §5).
PAPER_STAKE = 0.04
#: The paper's three markets by name: (scheme, stake).
MARKETS = {"delayed": ("delayed", 0.0), "outlier": ("outlier", 0.0), "staking": ("outlier", PAPER_STAKE)}


def default_theta() -> float:
    """Θ of the outlier scheme: its one definition is the rule's default (``schemes.outlier_weights``)."""

    return get_payment("outlier").defaults["theta"]
