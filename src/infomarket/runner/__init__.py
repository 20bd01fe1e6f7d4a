"""Running many simulations: ``execute`` (tasks of runs on any Executor, one warm-up per kernel),
``sweep`` (into a results store), ``run`` (``infomarket run``: one condition into a store), ``batch``
(the same in memory), ``plan`` (conditions and seeds), progress reporting."""
from .batch import BatchResult, run_batch

__all__ = ["BatchResult", "run_batch"]
