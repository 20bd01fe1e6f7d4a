"""The simulation engine: state as arrays (``world``), compiled step kernels (``kernels``, ``_loop``,
``specialise``), and the host that drives them (``simulation``)."""
from .simulation import Result, Simulation, simulate

__all__ = ["Result", "Simulation", "simulate"]
