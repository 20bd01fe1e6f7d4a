"""The store's tables: one folder of part files each, committed by the ``runs`` part (``Store.write_part``)."""

DATA_TABLES = ("robots", "history", "events", "payments", "sites", "configs", "chain")
#: Tables whose checksum and row count a commit record holds only when its part has rows: parts without
#: them keep the commit records (and digests) they had before the table existed.
OPTIONAL_TABLES = ("chain",)
TABLES = DATA_TABLES + ("runs",)
