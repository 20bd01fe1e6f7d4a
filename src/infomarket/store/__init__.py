"""Writing and reading results: atomic Parquet files and the results store of sweeps.

Layout (each part file written atomically, see ``files``)::

    STORE/store.json               format version, package version, creation time, master seed per experiment,
                                   hashes of the question and decision-rule files (analysis.declared)
    STORE/store.lock               held (an OS lock) by the one sweep writing the store
    STORE/robots/part-ID.parquet   one row per robot per run
    STORE/history/part-ID.parquet  wealth of every robot every K steps (when asked)
    STORE/events/part-ID.parquet   the ledger's event log: purchases, refusals, deposits (``--events``)
    STORE/payments/part-ID.parquet what each seller received at each deposit (``--events``)
    STORE/sites/part-ID.parquet    items per site per run (setups with terrain, docs/terrain.md)
    STORE/chain/part-ID.parquet    the chain model's measures per run (runs with [chain], docs/chain-model.md)
    STORE/configs/part-ID.parquet  the configuration each condition ran (JSON text), see ``config``
    STORE/runs/part-ID.parquet     one row per run: the commit record of its part
    STORE/damaged/...              parts that ``repair`` moved aside

Columns common to the tables: ``experiment`` (e.g. ``fig2A``), ``condition`` (a stable id such as
``byzantines=3,market=staking,rotation_angle=40``; ``base`` without a sweep), ``run``, ``seed``, and one
column per condition key (e.g. ``rotation_angle``).  A part counts only once its ``runs`` part exists:
the runs part is written last, so a crash leaves at most an orphan data part (robots, history, ...), which
readers ignore and the next sweep deletes.

**Integrity.**  The runs part records, for each other table, the SHA-256 and the row count of the part
it commits (columns ``robots_sha256``, ``robots_rows``, ...); the runs part itself is written with
Parquet page checksums and a SHA-256 of its own content (its values, not its bytes) in its Parquet
metadata (key ``infomarket_record_sha256``), so a commit record rewritten with one value changed is
caught too (stores made before that have ``record_checksums`` absent from ``store.json`` and are read as
before).  Every read checks them and raises ``StoreDamaged`` naming the part and the
repair command; ``verify`` lists every damaged and orphan part, ``repair`` moves damaged parts aside
(into ``damaged/``) so that their runs count as not done and the next sweep reruns exactly those.

Every column, with its unit, is described in ``store.dictionary`` (docs/data.md) and in each file's Parquet
field metadata.  Query with pandas (``Store(path).robots()``), ``Store(path).sql(query)`` (DuckDB, over the
verified parts only) or DuckDB directly::

    SELECT r.* FROM 'STORE/robots/*.parquet' r JOIN 'STORE/runs/*.parquet' USING (experiment, condition, run)
"""
from .files import write_parquet_atomic
from .results import Store, StoreDamaged, StoreError

__all__ = ["Store", "StoreDamaged", "StoreError", "write_parquet_atomic"]
