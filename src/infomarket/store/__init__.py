"""Writing and reading results: atomic Parquet files and the results store of sweeps."""
from .files import write_parquet_atomic
from .results import Store, StoreDamaged, StoreError

__all__ = ["Store", "StoreDamaged", "StoreError", "write_parquet_atomic"]
