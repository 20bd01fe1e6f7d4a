"""Hostile inputs a new user tried on the store, bench, attack-search, rl-train and the [chain] section:
each is one ``infomarket: error:`` line and exit 2 (or, in Python, an InfomarketError naming the argument),
with nothing written and nothing started; a [chain] value that cannot act in the run is one warning line."""
from __future__ import annotations

import os

import pytest

from infomarket.cli import main
from infomarket.config import sizes
from infomarket.errors import InfomarketError
from .refusals import refused, never


@pytest.fixture(autouse=True)
def limit(monkeypatch):
    monkeypatch.setenv(sizes.ENV, "16GiB")  # the same memory limit on every machine


# ------------------------------------------------------------------ store
@pytest.fixture
def empty_store(tmp_path):
    from infomarket.store import Store

    return Store(tmp_path / "st").create()


@pytest.mark.parametrize("query, words", [("", "the query is empty"), ("   ", "the query is empty"),
                                          (";", "holds no SQL statement"), ("-- c", "holds no SQL statement"),
                                          (" ; ; ", "holds no SQL statement")])
def test_store_sql_of_no_statement_is_one_error(query, words, empty_store, capsys):
    pytest.importorskip("duckdb")
    before = sorted(p.name for p in empty_store.root.rglob("*"))
    refused(capsys, ["store", "sql", str(empty_store.root), query], words)
    assert sorted(p.name for p in empty_store.root.rglob("*")) == before


def test_store_sql_takes_only_a_string(empty_store):
    from infomarket.store.results import SqlError

    for query in (None, 3, b"SELECT 1"):
        with pytest.raises(SqlError, match="the query must be a string"):
            empty_store.sql(query)


@pytest.mark.parametrize("table", ["robots", "runs", "history", "events", "payments", "sites", "chain", "configs"])
def test_a_missing_store_is_an_error_for_every_reader_as_for_sql(table, tmp_path):
    from infomarket.store import Store
    from infomarket.store.results import StoreError

    typo = Store(tmp_path / "typo")
    with pytest.raises(StoreError, match="not an infomarket results store"):
        getattr(typo, table)()
    with pytest.raises(StoreError, match="not an infomarket results store"):
        typo.sql("SELECT 1")
    assert not typo.root.exists()


def test_store_sql_help_names_every_table():
    from infomarket.cli import build_parser
    from infomarket.store.results import TABLES

    parser = build_parser()
    store = parser._subparsers._group_actions[0].choices["store"]
    text = store._subparsers._group_actions[0].choices["sql"].format_help()
    assert all(t in text for t in TABLES), text


# ------------------------------------------------------------------ bench
def test_bench_robots_beyond_memory_is_one_error_before_any_process(monkeypatch, capsys):
    import infomarket.bench

    monkeypatch.setattr(infomarket.bench, "run_swarm_sizes", never)
    refused(capsys, ["bench", "--robots", "25,100000000", "--steps", "10"], "--robots 100,000,000",
            "would need about", sizes.ENV)


def test_bench_env_batch_beyond_memory_is_one_error(monkeypatch, capsys):
    pytest.importorskip("gymnasium")
    import infomarket.bench.env

    monkeypatch.setattr(infomarket.bench.env, "run_env_bench", never)
    refused(capsys, ["bench", "--env", "--batch", "100000000", "--steps", "30"], "--batch 100000000",
            "100,000,000 runs at once", "would need about")


def test_bench_chain_without_robots_is_refused_not_ignored(monkeypatch, capsys):
    import infomarket.bench

    monkeypatch.setattr(infomarket.bench, "run_bench", never)
    refused(capsys, ["bench", "--chain", "--steps", "10"], "--chain goes with --robots")


# ------------------------------------------------------------------ rl-train
@pytest.mark.parametrize("option", ["--lr", "--sigma"])
@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "0", "-1"])
def test_rl_train_step_sizes_must_be_finite_and_positive(option, value, capsys):
    refused(capsys, ["rl-train", f"{option}={value}"], option, "finite number above 0")


def test_rl_train_refuses_a_population_beyond_memory_before_building_it(monkeypatch, tmp_path, capsys):
    pytest.importorskip("gymnasium")
    import infomarket.rl.envs

    monkeypatch.setattr(infomarket.rl.envs, "AttackVectorEnv", never)
    out = tmp_path / "r.json"
    refused(capsys, ["rl-train", "--iterations", "100000000", "--pairs", "100000", "--out", str(out)],
            "--pairs 100000", "200,000 runs at once", "would need about")
    # the learning curve, a float per iteration: 10**9 x 32 bytes = 29.8 GiB (by hand) > 16 GiB
    refused(capsys, ["rl-train", "--iterations", "1000000000", "--pairs", "1", "--out", str(out)],
            "learning curve 29.8 GiB")
    assert not out.exists()


def test_rl_train_refuses_a_blank_defence_or_out(monkeypatch, capsys):
    pytest.importorskip("gymnasium")
    import infomarket.rl.envs

    monkeypatch.setattr(infomarket.rl.envs, "AttackVectorEnv", never)
    refused(capsys, ["rl-train", "--defence", ""], "--defence ''")
    refused(capsys, ["rl-train", "--out", " "], "--out ' '")


def test_rl_train_takes_every_defence_the_search_takes():
    """The cells rl-train and the environments pick are the search's cells, `distinct` included."""
    import infomarket as im
    from infomarket.agents.runs import select_cell
    from infomarket.search import study

    s = study.load(im.load_experiment("attack_search"))
    for cell in study.cells(s):
        cfg = select_cell("attack_search", {"defence": cell.defence, "byzantines": cell.byzantines})
        assert cfg.payment.scheme == cell.config.payment.scheme
        assert cfg.swarm.groups[1].count == cell.byzantines
    assert "distinct" in {c.defence for c in study.cells(s)}


# ------------------------------------------------------------------ attack-search
@pytest.mark.parametrize("extra, words", [
    (["--defence", ""], ["--defence ''", "at least one defence"]),
    (["--defence", " , "], ["--defence ' , '", "at least one defence"]),
    (["--byzantines", ""], ["--byzantines ''", "at least one count"]),
    (["--race", "8,8"], ["race:", "each above the one before", "(got [8, 8])"]),
])
def test_attack_search_refuses_before_writing(extra, words, tmp_path, monkeypatch, capsys):
    import infomarket.search.driver

    monkeypatch.setattr(infomarket.search.driver, "search_cell", never)
    out = tmp_path / "as"
    refused(capsys, ["attack-search", "attack_search", *extra, "--out", str(out), "--quiet"], *words)
    assert not out.exists()


def test_attack_search_refuses_a_blank_out_and_writes_nothing_here(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for blank in ("", "  "):
        refused(capsys, ["attack-search", "attack_search", "--defence", "staking", "--out", blank], "--out")
    assert os.listdir(tmp_path) == []


def test_the_search_says_what_is_reduced(tmp_path):
    """Fewer cells, shorter runs and a smaller budget each mark the report reduced, --reduced or not."""
    from argparse import Namespace

    import infomarket as im
    from infomarket.search import study
    from infomarket.search.cli import _reductions

    exp = im.load_experiment("attack_search")
    declared = study.load(exp)
    every = study.cells(declared)
    same = Namespace(steps=None, transitory=None)
    assert _reductions(declared, declared, exp, every, every, same) == []
    assert _reductions(declared, declared, exp, every, every, Namespace(steps=exp.steps, transitory=None)) == []
    small = study.load(exp, budget=4, runs=1)
    got = _reductions(small, declared, exp, every[:1], every, Namespace(steps=60, transitory=20))
    assert got == [f"1 of {len(every)} cells", f"--steps 60 (declared {exp.steps})",
                   f"--transitory 20 (declared {exp.transitory})", f"--budget 4 (declared {declared.settings.budget})",
                   f"--popsize 4 (declared {declared.settings.popsize})",
                   f"--runs 1 (declared {declared.settings.runs})"]


def test_check_attack_search_shows_the_cells_the_search_runs_as_the_doc_says(capsys):
    """docs/attack-search.md: 8 defences x 1, 3, 8 Byzantines = 24 cells; the search's cells are counted
    by the search itself, `check` by the sweep planner."""
    import re
    from pathlib import Path

    import infomarket as im
    from infomarket.search import study

    doc = (Path(__file__).parents[1] / "docs" / "attack-search.md").read_text()
    defences, total = int(re.search(r"(\d+) defences x 1, 3, 8", doc).group(1)), 3 * int(
        re.search(r"(\d+) defences x 1, 3, 8", doc).group(1))
    cells = study.cells(study.load(im.load_experiment("attack_search")))
    assert len({c.defence for c in cells}) == defences and len(cells) == total
    assert main(["check", "attack_search"]) == 0
    out = capsys.readouterr().out
    assert f"defence ({defences} values)" in out and f"{total} conditions" in out
    assert f"{total} cells" in doc


# ------------------------------------------------------------------ [chain]
CHAIN = """
name = "c"
steps = 300
runs = 1

[swarm]
robots = 5

[[swarm.groups]]
behaviour = "naive"
count = 5

[chain]
{chain}
"""


def chain_file(tmp_path, *lines: str):
    p = tmp_path / "c.toml"
    p.write_text(CHAIN.format(chain="\n".join(lines)))
    return str(p)


@pytest.mark.parametrize("lines, words", [
    (['consensus = "poa"', "period = 500"], ["chain.period = 500", "no block"]),
    (['consensus = "poa"', "finality = 1000000000"], ["chain.finality = 1000000000", "final by depth"]),
    (['consensus = "poa"', "backbone = true", "latency = 10000000"], ["chain.latency = 10000000", "delivers nothing"]),
    (['consensus = "poa"', "partition = [400, 500]"], ["chain.partition = [400, 500]", "never partitioned"]),
])
def test_a_chain_value_that_cannot_act_in_the_run_is_one_warning_line(lines, words, tmp_path, capsys):
    assert main(["check", chain_file(tmp_path, *lines)]) == 0
    captured = capsys.readouterr()
    warned = [ln for ln in captured.err.splitlines() if ln.startswith("infomarket: warning: ")]
    assert len(warned) == 1 and all(w in warned[0] for w in words), captured.err
    assert "chain: poa" in captured.out


def test_quiet_silences_the_chain_warning_but_not_the_run(tmp_path, capsys):
    path = chain_file(tmp_path, 'consensus = "poa"', "partition = [400, 500]")
    assert main(["run", path, "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert main(["run", path, "--out", str(tmp_path / "o2")]) == 0
    warned = [ln for ln in capsys.readouterr().err.splitlines() if "warning" in ln]
    assert warned == ["infomarket: warning: chain.partition = [400, 500] starts at or after the run's end (steps "
                      "= 300): the network is never partitioned"]


def test_a_chain_that_acts_gives_no_warning_and_check_describes_it(tmp_path, capsys):
    path = chain_file(tmp_path, 'consensus = "poa"', "period = 5", "backbone = true", "latency = 3",
                      "partition = [100, 200]")
    assert main(["check", path]) == 0
    captured = capsys.readouterr()
    assert "warning" not in captured.err
    assert ("chain: poa, a block every 5 step(s) (out-of-turn delay 1), every robot signs; a backbone 3 step(s) late, "
            "message loss 0; gas price 0; finality 32 blocks, partitioned during steps [100, 200)") in captured.out


@pytest.mark.parametrize("lines, words", [
    (['consensus = "poa"', "latency = 5"], ["chain.latency = 5", "chain.backbone is false"]),
    (["period = 5"], ["chain.period = 5", 'consensus = "instant"']),
    (['consensus = "instant"', "signers = [1, 2]", "gas_price = 1.0"], ["chain.signers = [1, 2]", "chain.gas_price"]),
    (["partition = [10, 20]"], ["chain.partition", 'consensus = "instant"']),
])
def test_a_chain_key_that_contradicts_the_section_is_refused(lines, words, tmp_path, capsys):
    refused(capsys, ["check", chain_file(tmp_path, *lines)], *words)


def test_check_names_the_instant_ledger(tmp_path, capsys):
    assert main(["check", chain_file(tmp_path, 'consensus = "instant"')]) == 0
    assert "chain: instant" in capsys.readouterr().out


def test_the_python_api_warns_with_a_config_warning(tmp_path):
    import infomarket as im
    from infomarket.errors import ConfigWarning

    with pytest.warns(ConfigWarning, match="chain.period = 500"):
        im.load_experiment(chain_file(tmp_path, 'consensus = "poa"', "period = 500"))
    assert issubclass(ConfigWarning, InfomarketError)


# ------------------------------------------------------------------ names and the viewer
def test_an_empty_experiment_name_is_one_error(capsys):
    refused(capsys, ["check", ""], "experiment ''", "empty")


def test_view_quiet_prints_only_the_address(monkeypatch, capsys):
    from infomarket.viewer import cli

    line = "infomarket viewer: fig2B, 25 robots; open http://127.0.0.1:8765/"
    monkeypatch.setattr(cli, "QUIET", True)
    cli._announce(line)
    assert capsys.readouterr().out == "http://127.0.0.1:8765/\n"
    monkeypatch.setattr(cli, "QUIET", False)
    cli._announce(line)
    assert capsys.readouterr().out == line + "\n"


def test_the_figures_page_says_when_runs_are_shorter_than_the_paper_s():
    import pandas as pd

    from infomarket.analysis.report import length_notes

    runs = pd.DataFrame({"experiment": ["fig2B", "fig2B", "fig2A", "mine"], "steps": [4000, 4000, 15000, 10]})
    notes = length_notes(runs)
    assert len(notes) == 1 and notes[0].startswith("fig2B: runs of 4,000 steps") and "15,000 steps" in notes[0]


# ------------------------------------------------------------------ sizes that grow with the run's length
def test_run_refuses_steps_whose_tables_do_not_fit_in_its_worker_processes(monkeypatch, tmp_path, capsys):
    """One run of a billion steps fits in 16 GiB (its Lévy tables: 16 bytes x (10**9 + 1) = 14.9 GiB), but
    two worker processes each hold their own: 2 x 16 x (10**9 + 1) bytes = 29.8 GiB (by hand), refused."""
    import infomarket.runner.run

    monkeypatch.setattr(infomarket.runner.run, "sweep_locked", never)
    monkeypatch.setattr(infomarket.runner.run, "preflight", never)
    out = tmp_path / "D"
    refused(capsys, ["run", "fig2B", "--steps", "1000000000", "--workers", "2", "--out", str(out), "--quiet"],
            "2 worker processes", "1,000,000,000 steps", "would need about 29.8 GiB",
            "Lévy step-length table 29.8 GiB", "fewer --steps or --workers", sizes.ENV)
    assert not out.exists()


def test_run_names_steps_when_they_make_the_results_too_big(tmp_path, capsys):
    # fig5 keeps the wealth history every 100 steps: 32 runs x 25 robots x 10**6 samples x 32 bytes
    # = 23.8 GiB (by hand) of results
    out = tmp_path / "D"
    refused(capsys, ["run", "fig5", "--steps", "100000000", "--out", str(out), "--quiet"],
            "--runs 32 --steps 100000000:", "would need about 23.8 GiB")
    assert not out.exists()


def test_replay_refuses_an_event_log_beyond_memory_before_running(monkeypatch, tmp_path, capsys):
    """A replay records the event log: 25 robots x 10**8 steps x 0.5 events x 192 bytes = 223.5 GiB (by hand)."""
    import infomarket.viewer.recording

    monkeypatch.setattr(infomarket.viewer.recording, "record", never)
    out = tmp_path / "r.html"
    refused(capsys, ["replay", "fig2B", "--steps", "100000000", "--out", str(out), "--quiet"],
            "--steps 100000000", "event log 223.5 GiB", "fewer --steps or a larger --every")
    assert not out.exists()


def test_the_worlds_of_one_process_share_the_tables_the_estimate_counts_once():
    from infomarket.config import load_experiment

    cfg = load_experiment("fig2B").with_overrides(steps=1000)
    one = sizes.run_bytes(cfg)
    held = sizes.held_bytes(cfg, worlds=16, processes=3)
    assert held["Lévy step-length table"] == 3 * 16 * 1001  # once per process
    assert held["robot state"] == 3 * 16 * one["robot state"]  # once per world


def test_chain_demo_refuses_an_event_log_beyond_memory_before_simulating(monkeypatch, capsys):
    """The demo keeps the run's whole event log: 25 x 10**8 x 0.5 x 192 bytes = 223.5 GiB (by hand)."""
    pytest.importorskip("web3")
    import infomarket

    monkeypatch.setattr(infomarket, "simulate", never)
    refused(capsys, ["chain", "demo", "--steps", "100000000", "--robots", "25"],
            "--steps 100000000 --robots 25", "event log 223.5 GiB")
