"""Benchmarks: performance is measured here (``infomarket bench``, ``make bench``), never asserted in
tests.  ``setups``: the paper's setups against this machine's ``floor``; ``swarm``: robot-steps/s and
peak memory by swarm size; ``scaling``: sweep throughput by number of workers."""
from .floor import floor_steps_per_second
from .scaling import run_scaling
from .setups import run_bench
from .swarm import run_swarm_sizes

__all__ = ["floor_steps_per_second", "run_bench", "run_scaling", "run_swarm_sizes"]
