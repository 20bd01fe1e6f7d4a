"""Exception hierarchy: one root so callers can catch everything the package raises on purpose."""


class InfomarketError(Exception):
    """Root of every error infomarket raises deliberately."""


class ConfigError(InfomarketError, ValueError):
    """An experiment file or configuration is malformed; the message names the key and what is allowed."""


class SimulationError(InfomarketError, RuntimeError):
    """The compiled kernel reported a condition it cannot recover from (see engine.flags)."""
