"""Writing results: Parquet files written atomically (temporary file, then rename)."""
from .files import write_parquet_atomic

__all__ = ["write_parquet_atomic"]
