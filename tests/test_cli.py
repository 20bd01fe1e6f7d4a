"""The command line as a user meets it: run, bench, list, check, determinism of written files."""
import json
import sys

import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.seeds import run_seed
from infomarket.store import Store

COLUMNS = ["run", "seed", "robot", "behaviour", "honest", "drift", "items_collected", "wealth"]


def test_run_writes_robots_table_and_summary(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["run", "fig2B", "--runs", "3", "--steps", "600", "--seed", "5", "--out", str(out),
                 "--workers", "1"]) == 0
    df = Store(out).robots()
    assert all(c in df.columns for c in COLUMNS)
    assert set(df.experiment) == {"fig2B"} and set(df.condition) == {"base"}
    assert len(df) == 3 * 25 and sorted(df.run.unique()) == [0, 1, 2]
    assert list(df.seed.unique()) == [run_seed(5, i) for i in range(3)]
    assert df.groupby("run").honest.sum().tolist() == [24, 24, 24]
    assert df.groupby("run").wealth_share.sum().round(12).tolist() == [1.0, 1.0, 1.0]
    text = capsys.readouterr().out
    assert "saboteur" in text and "median items" in text and f"wrote the results store {out}" in text
    assert "3 runs x 600 steps, master seed 5" in text
    assert Store(out).history().empty


def test_same_seed_gives_identical_tables(tmp_path):
    tables = []
    for k, workers in enumerate(("1", "2")):
        out = tmp_path / f"o{k}"
        assert main(["run", "fig2D", "--runs", "2", "--steps", "2000", "--seed", "11", "--out", str(out),
                     "--workers", workers, "--quiet"]) == 0
        tables.append(Store(out).robots())
        parts = sorted(p.name for p in (out / "robots").glob("*.parquet"))
        assert parts == ["part-fig2D-base-00000-00000.parquet", "part-fig2D-base-00001-00001.parquet"]
    pd.testing.assert_frame_equal(tables[0], tables[1], check_exact=True)
    for run in (0, 1):  # the part files themselves are byte for byte the same
        name = f"part-fig2D-base-{run:05d}-{run:05d}.parquet"
        assert (tmp_path / "o0" / "robots" / name).read_bytes() == (tmp_path / "o1" / "robots" / name).read_bytes()
    out = tmp_path / "other"
    main(["run", "fig2D", "--runs", "2", "--steps", "2000", "--seed", "12", "--out", str(out), "--quiet"])
    assert not Store(out).robots().wealth.equals(tables[0].wealth)


def test_history_every_k_steps(tmp_path):
    out = tmp_path / "h"
    assert main(["run", "fig4A", "--runs", "2", "--steps", "1000", "--history", "100", "--out", str(out),
                 "--workers", "1", "--quiet"]) == 0
    h = Store(out).history()
    assert set(h.columns) >= {"run", "seed", "step", "robot", "wealth"}
    assert sorted(h.step.unique()) == list(range(100, 1001, 100))
    assert len(h) == 2 * 10 * 25
    last = h[h.step == 1000].sort_values(["run", "robot"]).wealth.to_numpy()
    robots = Store(out).robots().sort_values(["run", "robot"]).wealth.to_numpy()
    assert (last == robots).all()


def test_bench_json(capsys):
    assert main(["bench", "--json", "--steps", "300", "--repeats", "2"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report["setups"]) == {"fig2A", "fig2D", "fig4C", "fig4C+chain"}
    for r in report["setups"].values():
        assert r["steps_per_second"] > 0 and r["compile_seconds"] >= 0
    chain = report["setups"]["fig4C+chain"]  # its speed as a share of the instant ledger's, same run
    assert chain["ratio_to_instant"] == chain["steps_per_second"] / report["setups"]["fig4C"]["steps_per_second"]


def test_list_and_check(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for word in ("fig2A", "sceptical", "scaboteur", "greedy", "free_rider", "outlier", "theta=30.0"):
        assert word in out
    assert main(["check", "fig4C"]) == 0
    assert "20 sceptical, 5 scaboteur" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [["run"], ["bench", "--repeats", "x"], ["nonsense"]])
def test_usage_errors_exit_2(argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2


#: Libraries a command loads only when it runs: every command builds the whole parser before it starts,
#: and terrain-report's scipy.stats, imported with its parser, once added 0.45 s to each of them.
LOADED_BY_THEIR_COMMAND = ("scipy.stats", "matplotlib", "SALib", "web3", "distributed", "duckdb", "pettingzoo")

PARSER_IMPORTS = """
import sys
from infomarket.cli import build_parser
build_parser()
print(" ".join(sorted(name for name in sys.argv[1:] if name in sys.modules)))
"""


def test_building_the_parser_loads_no_library_that_only_a_command_needs(procs):
    proc = procs.run([sys.executable, "-c", PARSER_IMPORTS, *LOADED_BY_THEIR_COMMAND], check=True)
    assert proc.stdout.split() == []
