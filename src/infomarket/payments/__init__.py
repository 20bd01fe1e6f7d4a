"""Payment schemes, registered with ``infomarket.register_payment`` (the built-ins use the same API)."""
from . import schemes  # noqa: F401  (registration)
