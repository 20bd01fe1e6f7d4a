"""Writing and reading results: atomic Parquet files and the results store of sweeps."""
from .files import write_parquet_atomic
from .results import Store, StoreError

__all__ = ["Store", "StoreError", "write_parquet_atomic"]
