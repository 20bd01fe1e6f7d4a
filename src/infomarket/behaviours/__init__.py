"""Robot behaviours.  Each is a buy rule and a sell rule registered with ``infomarket.register_behaviour``;
the built-ins below use exactly that public API.  Helpers for writing rules are in ``behaviours.api``."""
from . import naive, sceptical, byzantine  # noqa: F401, I001  (registration order: byzantine reuses rules)
from . import api

__all__ = ["api"]
