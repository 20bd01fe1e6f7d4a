"""Analysis of simulation results (pandas in, pandas out), callable from notebooks."""
from .summary import summarise

__all__ = ["summarise"]
