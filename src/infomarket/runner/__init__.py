"""Running many simulations: seeds, batches over local processes, progress reporting."""
from .batch import BatchResult, run_batch

__all__ = ["BatchResult", "run_batch"]
