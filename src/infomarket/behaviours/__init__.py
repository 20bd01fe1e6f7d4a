"""Robot behaviours: buy rules and sell rules, plain functions over the world (``behaviours.api`` has the
helpers they call).  Nothing is registered on import: ``infomarket.builtins`` registers the built-ins
through the same public ``register_behaviour`` that users call."""
from . import api

__all__ = ["api"]
