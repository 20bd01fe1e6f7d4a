"""The data dictionary (issue 21 item 3): every column the store writes is described, in the Parquet
schema metadata and in docs/data.md, from one source (infomarket.store.dictionary); Store.sql reads only
verified parts and nothing else."""
from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.errors import InternalError
from infomarket.runner.design import make_design, save
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import run_sweep
from infomarket.store import Store, StoreDamaged
from infomarket.store.dictionary import CONDITION_KEY, TABLES, describe, markdown
from infomarket.store.results import DATA_TABLES, SqlError

ROOT = Path(__file__).parents[2]
DOC = ROOT / "docs" / "data.md"

# two food sites (the sites table), history, a grid key (condition keys), stakes (refused purchases),
# long enough for deposits (payments)
ALL = """
name = "all"
steps = 2500
runs = 1
seed = 3
history_every = 500

[[food]]
x = 200.0
y = 300.0

[[food]]
x = 700.0
y = 100.0

[swarm]
robots = 10

[[swarm.groups]]
behaviour = "sceptical"
count = 8

[[swarm.groups]]
behaviour = "scaboteur"
count = 2

[payment]
scheme = "outlier"
stake = 0.04

[sweep.grid]
"swarm.groups[1].params.rotation_angle" = [10.0, 60.0]
"""

# the chain model (the chain table and the robots' chain columns): a grid key too
CHAIN = """
name = "chained"
steps = 2000
runs = 2
seed = 4

[swarm]
robots = 25

[[swarm.groups]]
behaviour = "sceptical"
count = 20

[[swarm.groups]]
behaviour = "scaboteur"
count = 5

[payment]
scheme = "outlier"
stake = 0.04

[chain]
consensus = "poa"
period = 5
gas_price = 1e-7

[sweep.grid]
"swarm.groups[1].params.rotation_angle" = [60.0]
"""

SAMPLED = """
name = "design"
steps = 3
runs = 1
seed = 5

[swarm]
robots = 10

[[swarm.groups]]
behaviour = "sceptical"
count = 8

[[swarm.groups]]
behaviour = "scaboteur"
count = 2

[sweep.sample]
method = "sobol"
samples = 2
remainder = "swarm.groups[0].count"
outputs = ["items"]

[sweep.sample.bounds]
"robot.noise_sd" = [0.0, 0.1]
"swarm.groups[1].count" = { range = [1, 4], name = "byzantines" }
"""


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Store:
    tmp = tmp_path_factory.mktemp("dictionary")
    (tmp / "all.toml").write_text(ALL)
    (tmp / "design.toml").write_text(SAMPLED)
    (tmp / "chained.toml").write_text(CHAIN)
    s = Store(tmp / "store")
    run_sweep(conditions(im.load_experiment(tmp / "all.toml")), s, record_events=True)
    run_sweep(conditions(im.load_experiment(tmp / "chained.toml")), s)
    with s.lock():
        save(s, make_design(im.load_experiment(tmp / "design.toml")))
    return s


def _files(store: Store) -> dict[str, list[Path]]:
    out = {t: sorted((store.root / t).glob("part-*.parquet")) for t in DATA_TABLES + ("runs",)}
    out["designs"] = sorted((store.root / "designs").glob("*.parquet"))
    return out


def test_every_table_of_the_dictionary_is_written_by_the_test_sweep(store):
    files = _files(store)
    assert set(files) == set(TABLES)
    assert all(files[t] for t in TABLES), {t: len(f) for t, f in files.items()}


def test_every_written_column_carries_its_unit_and_description(store):
    seen = 0
    for table, paths in _files(store).items():
        for path in paths:
            schema = pq.read_schema(path)
            assert schema.metadata[b"infomarket_table"] == table.encode()
            for field in schema:
                entry = describe(table, field.name, keys=["rotation_angle"])
                assert entry is not None, f"{table}.{field.name} is written but not in the data dictionary"
                meta = field.metadata or {}
                assert meta.get(b"unit") == entry.unit.encode(), (table, field.name)
                assert meta.get(b"description") == entry.description.encode(), (table, field.name)
                seen += 1
    assert seen > 60


def test_the_listed_columns_are_the_written_ones(store):
    """No entry describes a column that is never written (the dictionary would lie), and the condition
    key is there as a condition key."""
    written: dict[str, set[str]] = {}
    for table, paths in _files(store).items():
        for path in paths:
            written.setdefault(table, set()).update(pq.read_schema(path).names)
    for name, t in TABLES.items():
        listed = {c.name for c in t.columns if c.name not in ("NAME", "NAME_raw")}
        assert listed <= written[name], f"{name}: listed but never written: {listed - written[name]}"
    for table in ("robots", "events", "payments", "sites", "chain", "runs"):
        assert "rotation_angle" in written[table]
        assert describe(table, "rotation_angle", ["rotation_angle"]) == CONDITION_KEY
    assert {"point", "noise_sd_raw", "noise_sd", "byzantines_raw", "byzantines"} == written["designs"]


def test_the_chain_table_holds_each_chain_runs_measures_and_nothing_else_changes(store):
    chain = store.chain()
    assert len(chain) == 2 and set(chain.experiment) == {"chained"}
    robots = store.robots()
    for row in chain.itertuples():
        rerun = im.Simulation(store.config("chained", row.condition), int(row.seed))
        rerun.run()
        m = rerun.chain_measures()
        for k in ("blocks", "height", "forks", "reorgs", "reorganised_tx", "view_reorgs", "failed_tx",
                  "pending_tx", "deposits_paid"):
            assert getattr(row, k) == m[k], k
        mine = robots[(robots.experiment == "chained") & (robots.run == row.run)].sort_values("robot")
        assert mine.gas_paid.tolist() == m["gas_paid"] and mine.mean_lag.tolist() == m["mean_lag"]
        assert row.gas_paid == pytest.approx(sum(m["gas_paid"])) and row.gas_paid > 0  # gas_price > 0
        assert row.mean_lag == pytest.approx(np.mean(m["mean_lag"]))
    # runs on the instant ledger: no chain columns in their robots files, none in their commit records
    for pid in store.committed():
        record = pd.read_parquet(store.part_path("runs", pid))
        names = set(pq.read_schema(store.part_path("robots", pid)).names)
        chained = set(record.experiment) == {"chained"}
        assert ("chain_sha256" in record.columns) == chained == store.part_path("chain", pid).exists()
        assert ({"gas_paid", "mean_lag"} <= names) == chained
    df = store.sql("SELECT r.behaviour, avg(r.gas_paid) AS gas, count(*) AS n FROM robots r "
                   "JOIN chain USING (experiment, condition, run) GROUP BY ALL ORDER BY r.behaviour")
    assert df.n.tolist() == [10, 40] and (df.gas > 0).all()


def test_a_chain_part_its_record_does_not_list_is_damage(store, tmp_path):
    s = _copy(store, tmp_path / "copy")
    plain = next(pid for pid in s.committed()
                 if set(pd.read_parquet(s.part_path("runs", pid)).experiment) == {"all"})
    chained = next(pid for pid in s.committed() if s.part_path("chain", pid).exists())
    s.part_path("chain", plain).write_bytes(s.part_path("chain", chained).read_bytes())
    with pytest.raises(StoreDamaged, match="does not list it"):
        s.chain()


def test_wealth_share_is_a_fraction_in_the_files(store):
    robots = store.robots()
    per_run = robots.groupby(["experiment", "condition", "run"]).wealth_share.sum()
    assert per_run.round(12).eq(1.0).all()  # fractions of the run's wealth add up to 1, not to 100
    assert "fraction" in describe("robots", "wealth_share").unit


def test_a_column_without_an_entry_is_refused_before_anything_is_written(tmp_path):
    s = Store(tmp_path / "s").create()
    robots = pd.DataFrame({"experiment": ["x"], "condition": ["base"], "run": [0], "mystery": [1.0]})
    runs = pd.DataFrame({"experiment": ["x"], "condition": ["base"], "run": [0]})
    with pytest.raises(InternalError, match="mystery"):
        s.write_part("p", robots, runs)
    assert not list((tmp_path / "s" / "robots").glob("*.parquet"))
    assert not s.committed()


def test_the_doc_shows_exactly_the_dictionary():
    text = DOC.read_text()
    for name in TABLES:
        assert f"### {name}\n" in text
        assert markdown(name) in text, f"docs/data.md's {name} table differs from infomarket.store.dictionary"
    documented = set(re.findall(r"^### (\w+)$", text.split("## Tables", 1)[1], re.M))
    assert documented == set(TABLES)
    assert "fraction" in text and "percentage" in text  # wealth_share's two forms are named


def test_sql_reads_the_committed_parts(store):
    df = store.sql("SELECT kind, count(*) AS n FROM events GROUP BY ALL ORDER BY kind")
    counts = store.events().kind.value_counts()
    assert dict(zip(df.kind, df.n)) == {k: int(v) for k, v in counts.items() if v}
    n = store.sql("SELECT count(*) AS n FROM robots JOIN runs USING (experiment, condition, run)").n[0]
    assert n == len(store.robots()) == 70  # 2 runs of 10 on the instant ledger, 2 of 25 on the chain


def test_the_documented_sql_command_runs(store, tmp_path, monkeypatch, capsys):
    block = re.search(r"```shell\n(infomarket store sql .*?)\n```", DOC.read_text()).group(1)
    words = shlex.split(block)
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "fig2B").symlink_to(store.root.resolve())
    monkeypatch.chdir(tmp_path)
    assert main(words[1:]) == 0
    out = capsys.readouterr().out
    assert "share_pct" in out and "sceptical" in out and "scaboteur" in out


def _copy(store: Store, dest: Path) -> Store:
    import shutil

    shutil.copytree(store.root, dest)
    return Store(dest)


def test_sql_ignores_orphans_and_refuses_or_skips_damaged_parts(store, tmp_path):
    s = _copy(store, tmp_path / "copy")
    total = len(s.robots())
    one = s.committed()[0]
    # an orphan (a data part with no commit record) is never read
    orphan = s.part_path("robots", "orphan-part")
    orphan.write_bytes(s.part_path("robots", one).read_bytes())
    assert s.sql("SELECT count(*) AS n FROM robots").n[0] == total
    # a damaged part: refused like every read, or left out on request
    path = s.part_path("robots", one)
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(StoreDamaged, match="repair"):
        s.sql("SELECT count(*) AS n FROM robots")
    rows_of_one = int(pd.read_parquet(s.part_path("runs", one)).robots_rows.sum())
    left = s.sql("SELECT count(*) AS n FROM robots", skip_damaged=True).n[0]
    assert left == total - rows_of_one
    runs_left = s.sql("SELECT count(*) AS n FROM runs", skip_damaged=True).n[0]
    others = sum(len(pd.read_parquet(s.part_path("runs", pid))) for pid in s.committed() if pid != one)
    assert runs_left == others  # the other parts only


def test_sql_reads_and_writes_no_other_file(store, tmp_path, capsys):
    target = tmp_path / "out.csv"
    with pytest.raises(SqlError, match="disabled"):
        store.sql(f"COPY robots TO '{target}'")
    assert not target.exists()
    with pytest.raises(SqlError):
        store.sql("SELECT * FROM read_csv('/etc/passwd')")
    # from the command line: one message, exit 2
    assert main(["store", "sql", str(store.root), "SELECT * FROM nowhere"]) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error:") == 1 and "nowhere" in err and "Traceback" not in err


@pytest.mark.parametrize("meta", ["{not json", "[1, 2]", None])
@pytest.mark.parametrize("action", ["verify", "failed", "repair", "sql"])
def test_an_unreadable_store_json_is_one_message_not_an_empty_store(tmp_path, capsys, meta, action):
    """Before: `store verify` on a store whose store.json was garbage (or a folder) said "0 committed
    part(s), 0 damaged" and exited 0; a JSON list crashed the sweep with an AttributeError."""
    root = tmp_path / "s"
    root.mkdir()
    if meta is None:
        (root / "store.json").mkdir()
    else:
        (root / "store.json").write_text(meta)
    argv = ["store", action, str(root)] + (["SELECT 1"] if action == "sql" else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error:") == 1 and "store.json" in err and "Traceback" not in err
    assert sorted(p.name for p in root.iterdir()) == ["store.json"]  # nothing written
