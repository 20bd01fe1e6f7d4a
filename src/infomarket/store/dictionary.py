"""The data dictionary: every table and column the results store writes, with its unit and meaning.

The one source of truth for ``docs/data.md`` (``tests/store/test_dictionary.py`` compares the page with
``TABLES`` and checks that every column a sweep writes has an entry) and for the Parquet schema metadata
the store writes: each field of a part carries ``unit`` and ``description`` (pyarrow field metadata),
the file carries ``infomarket_table``.

Besides the columns listed, a table may have **condition keys**: one column per key of the experiment's
``[sweep]`` (a grid key's last path element such as ``rotation_angle``, an axis name such as ``market``,
or ``point`` and the sampled keys of a ``[sweep.sample]`` design) holding the value this condition sets.
They are described by ``CONDITION_KEY``.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import pyarrow as pa

from ..errors import InternalError


@dataclass(frozen=True)
class Column:
    """One column of a store table as the data dictionary documents it: name, type, unit and meaning."""
    name: str
    type: str  # the Arrow/pandas type as written (int64, uint64, float64, string, bool, category)
    unit: str  # "" when the column has no unit (an id, a code, a text)
    description: str


@dataclass(frozen=True)
class Table:
    """One store table as documented: where its parts live, what a row is, its key and its columns."""
    name: str
    path: str  # where in the store
    rows: str  # what one row is
    key: tuple[str, ...]  # the columns to join and sort on
    columns: tuple[Column, ...]
    condition_keys: bool  # whether the table also carries the condition keys

    def column(self, name: str) -> Column | None:
        """The column called ``name``, or None if the table has none."""
        for c in self.columns:
            if c.name == name:
                return c
        return None


def _c(name, type_, unit, description) -> Column:
    return Column(name, type_, unit, description)


EXPERIMENT = _c("experiment", "string", "", "the experiment's name (its file's `name`, e.g. `fig2A`)")
CONDITION = _c("condition", "string", "",
               "the condition's id: its keys as `key=value` joined by commas, sorted (e.g. "
               "`byzantines=3,market=staking,rotation_angle=40`); `base` for an experiment without `[sweep]`")
RUN = _c("run", "int64", "", "the run's number within its condition, 0, 1, 2, ...")
SEED = _c("seed", "uint64", "", "the run's own seed (derived from the master seed, the run and the condition; "
                                "`simulate(store.config(experiment, condition), seed)` reruns it)")
STEP = _c("step", "int64", "step", "the simulation step (the first step is 1)")
ROBOT_BEHAVIOUR = _c("behaviour", "category", "", "the robot's behaviour (`infomarket list` names them)")
ROBOT_HONEST = _c("honest", "bool", "", "whether the behaviour is honest (false: Byzantine)")

CONDITION_KEY = Column("(condition key)", "as the key", "as the configuration key it sets (docs/model.md §1)",
                       "condition key: the value this condition sets for one key of the experiment's `[sweep]`")

SITE_CODES = "0 = food, 1 = nest"

_DATA = ("robots", "history", "events", "payments", "sites", "configs")
CHAIN_ONLY = "Runs with the chain model only (`[chain] consensus = \"poa\"`, docs/chain-model.md); absent from " \
             "other runs' files (NULL in SQL over a store holding both)"

TABLES: dict[str, Table] = {t.name: t for t in (
    Table("robots", "robots/part-*.parquet", "one robot at the end of one run",
          ("experiment", "condition", "run", "robot"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("robot", "int64", "", "the robot's number in its run, 0 to robots - 1, in the order of "
                                       "`[[swarm.groups]]`"),
              ROBOT_BEHAVIOUR, ROBOT_HONEST,
              _c("drift", "float64", "degrees per step",
                 "the robot's odometry bias mu_i: the mean of the angle its movement is turned by each step "
                 "(signed; docs/model.md §1)"),
              _c("items_collected", "int64", "items",
                 "items the robot deposited in the nest after the transitory period"),
              _c("wealth", "float64", "money (initial wealth = payment.initial_wealth, 1 by default)",
                 "the robot's balance at the end of the run"),
              _c("wealth_share", "float64", "fraction (0 to 1)",
                 "wealth over the total wealth of the robots of its run; a FRACTION in the files (0.04 is "
                 "an equal share among 25), shown as a PERCENTAGE in printed tables and figures"),
              _c("gas_paid", "float64", "money", "gas the robot paid on the canonical chain (gas_price x the "
                                                 f"measured gas of its reveals and deposits). {CHAIN_ONLY}"),
              _c("mean_lag", "float64", "blocks", "the robot's mean view lag: canonical height minus its head's "
                                                  f"height, averaged over the run's steps. {CHAIN_ONLY}"),
          ), True),
    Table("history", "history/part-*.parquet", "one robot's wealth at one recorded step of one run "
                                               "(runs made with `history_every = K` / `--history K`)",
          ("experiment", "condition", "run", "step", "robot"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("step", "int64", "step", "the step at whose end the wealth was read: K, 2K, 3K, ... (no row "
                                          "for the start; docs/model.md §7)"),
              _c("robot", "int64", "", "the robot's number (joins robots.robot)"),
              _c("wealth", "float64", "money", "the robot's balance at the end of that step"),
              ROBOT_HONEST, ROBOT_BEHAVIOUR,
          ), False),
    Table("events", "events/part-*.parquet", "one ledger event of one run (sweeps with `--events`)",
          ("experiment", "condition", "run", "step"), (
              EXPERIMENT, CONDITION, RUN, SEED, STEP,
              _c("kind", "category", "", "`purchase` (a buyer bought a seller's information), `refused` (a "
                                         "purchase refused: the seller could not lock its stake) or `deposit` "
                                         "(the buyer deposited an item in the nest; the scheme then pays its "
                                         "sellers)"),
              _c("buyer", "int64", "", "the buying robot (for a deposit: the depositing robot)"),
              _c("seller", "int64", "", "the selling robot; -1 for a deposit"),
              _c("site", "int64", "", f"the site the information is about: {SITE_CODES}; -1 for a deposit"),
              _c("direction_deg", "float64", "degrees",
                 "direction of the bought vector in the buyer's frame (x axis along its heading)"),
              _c("x", "float64", "arena units", "the bought vector in the buyer's frame, x"),
              _c("y", "float64", "arena units", "the bought vector in the buyer's frame, y"),
              _c("age", "int64", "steps", "the age of the bought information"),
              _c("stake", "float64", "money", "the stake the seller locked for this purchase (0 without staking)"),
              _c("seller_x", "float64", "arena units", "the seller's position in the buyer's frame, x"),
              _c("seller_y", "float64", "arena units", "the seller's position in the buyer's frame, y"),
          ), True),
    Table("payments", "payments/part-*.parquet", "one transaction settled at a deposit, in one run "
                                                 "(sweeps with `--events`)",
          ("experiment", "condition", "run", "step", "seller"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("step", "int64", "step", "the step of the buyer's deposit that settled the transaction"),
              _c("buyer", "int64", "", "the depositing buyer (joins events.buyer of a `deposit`)"),
              _c("seller", "int64", "", "the transaction's seller (joins robots.robot)"),
              _c("site", "int64", "", f"the site of the information: {SITE_CODES}"),
              _c("weight", "float64", "fraction (0 to 1)",
                 "the seller's normalised weight in the settlement (0: weighed out as an outlier)"),
              _c("amount", "float64", "money", "what the seller received: weight x (information_share x reward + "
                                               "the stakes pooled by the buyer's transactions); 0 when weighed out"),
          ), True),
    Table("sites", "sites/part-*.parquet", "one food site or nest of one run (setups with terrain, "
                                           "docs/terrain.md)",
          ("experiment", "condition", "run", "site"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("site", "int64", "", "the site's number in its run: food sites first, in file order, then nests"),
              _c("kind", "string", "", "`food` or `nest`"),
              _c("x", "float64", "arena units", "the site's centre, x"),
              _c("y", "float64", "arena units", "the site's centre, y"),
              _c("radius", "float64", "arena units", "the site's radius"),
              _c("items", "int64", "items", "items picked up at this food site, or deposited at this nest, after "
                                            "the transitory period"),
          ), True),
    Table("chain", "chain/part-*.parquet", "the chain model's measures of one run (runs with `[chain] "
                                           "consensus = \"poa\"` only, docs/chain-model.md)",
          ("experiment", "condition", "run"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("blocks", "int64", "blocks", "blocks made on every branch"),
              _c("height", "int64", "blocks", "the canonical chain's height at the end (genesis 0)"),
              _c("forks", "int64", "blocks", "blocks made on a parent that already had a child"),
              _c("reorgs", "int64", "reorganisations", "times the canonical head moved to a block not descending "
                                                       "from it"),
              _c("reorganised_tx", "int64", "transactions", "transactions those moves took out of the canonical "
                                                            "chain (payments undone, redone if included again)"),
              _c("view_reorgs", "int64", "reorganisations", "times a robot's head moved to a block not descending "
                                                            "from it, summed over the robots"),
              _c("failed_tx", "int64", "transactions", "included transactions that failed (the branch could not "
                                                       "pay the stake and gas), at their first application"),
              _c("pending_tx", "int64", "transactions", "transactions not yet in a final block at the end"),
              _c("deposits_paid", "int64", "payments", "deposits paid by a block (once per paying block: a "
                                                       "payment redone on another branch counts again)"),
              _c("mean_payment_delay", "float64", "steps", "mean steps from a deposit to the block that paid it "
                                                           "(NaN when no deposit was paid)"),
              _c("gas_paid", "float64", "money", "gas paid on the canonical chain by all robots together"),
              _c("mean_lag", "float64", "blocks", "the robots' mean view lag (robots.mean_lag averaged over the "
                                                  "run's robots)"),
          ), True),
    Table("configs", "configs/part-*.parquet", "the configuration one condition ran (one per part; "
                                               "`Store.configs()` drops duplicates)",
          ("experiment", "condition", "config_hash"), (
              EXPERIMENT, CONDITION,
              _c("config_hash", "string", "", "hash of the configuration (joins runs.config_hash)"),
              _c("config", "string", "JSON", "the whole validated configuration as JSON text "
                                             "(`Store.config(experiment, condition)` reads it back)"),
          ), False),
    Table("runs", "runs/part-*.parquet", "one run: the commit record of its part (a run counts only once "
                                         "this row exists)",
          ("experiment", "condition", "run"), (
              EXPERIMENT, CONDITION, RUN, SEED,
              _c("master_seed", "int64", "", "the experiment's master seed"),
              _c("config_hash", "string", "", "hash of the configuration the run used"),
              _c("package_version", "string", "", "the infomarket version that made the run"),
              _c("duration_s", "float64", "seconds", "wall time the run took (compiling excluded)"),
              _c("steps", "int64", "steps", "steps the run simulated"),
              _c("transitory", "int64", "steps", "steps at the start whose items are not counted"),
              _c("status", "string", "", "`ok`, or `failed` (the run raised; no data rows, see `error`)"),
              _c("error", "string", "", "why a failed run failed (the error's text; empty when ok)"),
              *(c for t in _DATA for c in (
                  _c(f"{t}_sha256", "string", "", f"SHA-256 of the part's {t} file (empty: the part has no "
                                                  f"{t} rows)"),
                  _c(f"{t}_rows", "int64", "rows", f"rows of the part's {t} file"))),
              _c("chain_sha256", "string", "", f"SHA-256 of the part's chain file. {CHAIN_ONLY}"),
              _c("chain_rows", "int64", "rows", f"rows of the part's chain file. {CHAIN_ONLY}"),
          ), True),
    Table("designs", "designs/EXPERIMENT.parquet", "one point of a sampled design (`[sweep.sample]`); the "
                                                   "settings are beside it in designs/EXPERIMENT.json",
          ("point",), (
              _c("point", "int64", "", "the point's number (its runs have condition `point=N`)"),
              Column("NAME_raw", "float64", "as the key", "for each sampled key NAME: the raw draw of the "
                                                           "sampler, before rounding"),
              Column("NAME", "float64 or int64", "as the key", "for each sampled key NAME: the value the point "
                                                               "sets (integer keys rounded into their range)"),
          ), False),
)}


def describe(table: str, name: str, keys: Iterable[str] = ()) -> Column | None:
    """The entry of column ``name`` of ``table``; condition keys named in ``keys`` get ``CONDITION_KEY``;
    a design's NAME / NAME_raw columns the pattern entries.  None when the column has no entry."""
    t = TABLES[table]
    found = t.column(name)
    if found is not None:
        return found
    if t.condition_keys and name in set(keys):
        return CONDITION_KEY
    if table == "designs":
        return t.column("NAME_raw" if name.endswith("_raw") else "NAME")
    return None


def annotate(table: str, data: pa.Table, keys: Iterable[str] = ()) -> pa.Table:
    """``data`` with each field's ``unit`` and ``description`` in its Arrow field metadata and the table's
    name in the schema metadata (``infomarket_table``).  A column without an entry is a defect of
    infomarket (InternalError): add it to ``TABLES`` (and docs/data.md)."""
    keys = list(keys)
    fields = []
    for f in data.schema:
        entry = describe(table, f.name, keys)
        if entry is None:
            raise InternalError(f"the store's {table} table got a column {f.name!r} that the data dictionary "
                                f"(infomarket.store.dictionary) does not describe")
        meta = {**(f.metadata or {}), b"unit": entry.unit.encode(), b"description": entry.description.encode()}
        fields.append(f.with_metadata(meta))
    meta = {**(data.schema.metadata or {}), b"infomarket_table": table.encode()}
    return data.cast(pa.schema(fields, metadata=meta))


def markdown(table: str) -> str:
    """The columns of ``table`` as the Markdown table docs/data.md shows (the test compares them)."""
    lines = ["| column | type | unit | meaning |", "|---|---|---|---|"]
    for c in TABLES[table].columns:
        lines.append(f"| `{c.name}` | {c.type} | {c.unit or '—'} | {c.description.replace('|', '/')} |")
    if TABLES[table].condition_keys:
        k = CONDITION_KEY
        lines.append(f"| *condition keys* | {k.type} | {k.unit} | {k.description} |")
    return "\n".join(lines) + "\n"
