"""Hostile inputs by family, as a new user tries them: every file read is checked before it is trusted,
every number is bounded where the model needs it, every resource asked for is checked before it is taken,
every option's value is checked before work starts.  Each case ends in one ``infomarket: error:`` line
and exit 2, with no traceback and nothing written (or runs correctly).  The cases are drawn from each
family, beyond the ones a probe happened to try."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from infomarket.cli import main
from infomarket.config import sizes
from .refusals import refused, never


@pytest.fixture(autouse=True)
def limit(monkeypatch):
    monkeypatch.setenv(sizes.ENV, "16GiB")  # the same memory limit on every machine


MINIMAL = """name = "tiny"
steps = 50
[swarm]
robots = 5
groups = [{ behaviour = "naive", count = 4 }, { behaviour = "saboteur", count = 1 }]
"""


# ------------------------------------------------------------------ numbers bounded where the model needs them
@pytest.mark.parametrize("section, key, value", [
    ("robot", "speed", "1e300"), ("robot", "speed", "1e12"), ("robot", "communication_range", "1e300"),
    ("robot", "radius", "1e300"), ("robot", "bias_mean", "-1e300"), ("robot", "bias_sd", "1e300"),
    ("robot", "noise_sd", "1e300"), ("robot", "fuel_cost", "1e300"), ("robot", "stop_time", "9223372036854775807"),
    ("robot", "cooldown", "9223372036854775807"), ("payment", "reward", "1e308"),
    ("payment", "initial_wealth", "1e308"), ("payment", "stake", "1e300"),
    ("payment", "stake_expiry", "9223372036854775807"),
    ("arena", "width", "1e300"), ("random_walk", "rho", "0.999999999999999"), ("chain", "gas_price", "1e300"),
    ("chain", "latency", "9223372036854775807"),
])
def test_a_number_the_model_cannot_take_is_refused_by_check(section, key, value, tmp_path, capsys):
    """Each passed validation before and then failed (ZeroDivisionError, OverflowError) or stored inf and
    NaN: a number is finite and below the bound its use needs (schema.MAX_LENGTH, MAX_MONEY, MAX_STEPS)."""
    f = tmp_path / "big.toml"
    f.write_text(MINIMAL + f"[{section}]\n{key} = {value}\n")
    refused(capsys, ["check", str(f)], f"{section}.{key}")


@pytest.mark.parametrize("table, value", [("payment.params", "theta = 1e300"),
                                          ("swarm.groups[0].params", None)])
def test_rule_parameters_are_bounded_too(table, value, tmp_path, capsys):
    f = tmp_path / "p.toml"
    if value is None:
        f.write_text(MINIMAL.replace('{ behaviour = "saboteur", count = 1 }',
                                     '{ behaviour = "saboteur", count = 1, params = { rotation_angle = 1e300 } }'))
        refused(capsys, ["check", str(f)], "rotation_angle")
    else:
        f.write_text(MINIMAL + f'[payment]\nscheme = "outlier"\n[payment.params]\n{value}\n')
        refused(capsys, ["check", str(f)], "theta")


def test_the_bounds_keep_the_paper_values_valid(capsys):
    """The shipped experiments, the paper's among them, are inside every bound (a bound that broke them
    would change the paper's results)."""
    from infomarket.config import load_experiment, shipped_experiments

    for name in shipped_experiments():
        load_experiment(name)


# ------------------------------------------------------------------ files read: checked before they are trusted
def _big_toml(path: Path) -> Path:
    """A valid experiment file of more than the size limit: the experiment, then a comment of megabytes."""
    path.write_text(MINIMAL + "# " + "x" * (5 * 2**20) + "\n")
    return path


def _fifo(path: Path) -> Path:
    os.mkfifo(path)  # no writer: reading it would block forever
    return path


def _device_link(path: Path) -> Path:
    path.symlink_to("/dev/zero")  # a device that never ends, behind a name with the right suffix
    return path


@pytest.mark.parametrize("make, words", [(lambda p: _big_toml(p / "big.toml"), "at most"),
                                         (lambda p: _fifo(p / "pipe.toml"), "not a regular file"),
                                         (lambda p: _device_link(p / "zero.toml"), "not a regular file"),
                                         (lambda p: Path("/dev/zero"), "not a regular file"),
                                         (lambda p: Path("/dev/null"), "not a regular file")],
                         ids=["big", "fifo", "devlink", "devzero", "devnull"])
@pytest.mark.parametrize("command", [["check"], ["run", "--runs", "1", "--steps", "10", "--quiet"]])
def test_an_experiment_that_is_not_a_regular_file_of_a_sane_size_is_refused_unread(make, words, command,
                                                                                    tmp_path, capsys, monkeypatch):
    path = make(tmp_path)
    monkeypatch.chdir(tmp_path)
    refused(capsys, [command[0], str(path), *command[1:]], str(path), words)
    assert not (tmp_path / "results").exists()


def test_load_experiment_refuses_the_same_in_python(tmp_path):
    from infomarket.config import load_experiment
    from infomarket.errors import ConfigError

    with pytest.raises(ConfigError, match="at most"):
        load_experiment(_big_toml(tmp_path / "big.toml"))
    with pytest.raises(ConfigError, match="not a regular file"):
        load_experiment(_fifo(tmp_path / "p.json"))


@pytest.mark.parametrize("make", [lambda f: (f.unlink(), os.mkfifo(f)),
                                  lambda f: f.write_text(" " * (5 * 2**20) + "{}"),
                                  lambda f: (f.unlink(), f.symlink_to("/dev/zero"))], ids=["fifo", "big", "devlink"])
@pytest.mark.parametrize("action", ["verify", "failed"])
def test_a_store_json_that_is_not_a_regular_file_of_a_sane_size_is_refused_unread(make, action, tmp_path, capsys):
    from infomarket.store import Store

    store = Store(tmp_path / "st").create()
    make(store.meta_path)
    refused(capsys, ["store", action, str(store.root)], "store.json")


# ------------------------------------------------------------------ the original JSON format: types named
LEGACY = {"width": 1200, "height": 600, "simulation_steps": 100, "number_runs": 1,
          "behaviors": [{"class": "NaiveBehavior", "population_size": 4, "parameters": {}},
                        {"class": "SaboteurBehavior", "population_size": 1, "parameters": {}}],
          "payment_system": {"class": "DelayedPaymentPaymentSystem", "initial_reward": 1,
                             "parameters": {"information_share": 0.5}},
          "market": {"class": "FixedPriceMarket", "parameters": {"reward": 1}}}


def _legacy(**changes) -> dict:
    data = json.loads(json.dumps(LEGACY))
    for path, value in changes.items():
        *keys, last = path.split("__")
        where = data
        for k in keys:
            where = where[int(k)] if k.isdigit() else where[k]
        where[last] = value
    return data


@pytest.mark.parametrize("changes, words", [
    ({"behaviors__0__class": ["NaiveBehavior"]}, "behaviors[0].class"),
    ({"behaviors__0__class": {"name": "NaiveBehavior"}}, "behaviors[0].class"),
    ({"behaviors__1__class": 3}, "behaviors[1].class"),
    ({"behaviors__0__parameters": 5}, "behaviors[0].parameters"),
    ({"behaviors__0__parameters": [1, 2]}, "behaviors[0].parameters"),
    ({"payment_system__class": {"DelayedPaymentPaymentSystem": 1}}, "payment_system.class"),
    ({"payment_system__class": ["DelayedPaymentPaymentSystem"]}, "payment_system.class"),
    ({"payment_system__parameters": 5}, "payment_system.parameters"),
    ({"payment_system__parameters": ["information_share"]}, "payment_system.parameters"),
    ({"market__class": ["FixedPriceMarket"]}, "market.class"),
    ({"market__parameters": 5}, "market.parameters"),
    ({"behaviors": {"class": "NaiveBehavior"}}, "behaviors"),
    ({"behaviors": ["NaiveBehavior"]}, "behaviors[0]"),
])
def test_the_original_formats_type_errors_are_named(changes, words, tmp_path, capsys):
    f = tmp_path / "orig.json"
    f.write_text(json.dumps(_legacy(**changes)))
    refused(capsys, ["check", str(f)], words)


# ------------------------------------------------------------------ resources checked before they are taken
@pytest.mark.parametrize("argv", [["run", "fig2B"], ["sweep", "fig2B", "--out", "o"], ["demo"],
                                  ["attack-search", "attack_search", "--out", "o"],
                                  ["defence-search", "attack_search", "--out", "o"],
                                  ["adaptive-attack", "attack_search", "--defence", "staking", "--byzantines", "3",
                                   "--budget", "5", "--out", "o"]])
@pytest.mark.parametrize("workers", ["100000", "1000", str(10**30)])
def test_workers_beyond_what_a_machine_can_use_are_refused_before_work(argv, workers, capsys, tmp_path, monkeypatch):
    from infomarket.cliargs import max_workers

    monkeypatch.chdir(tmp_path)
    assert int(workers) > max_workers()
    refused(capsys, [*argv, "--workers", workers], "--workers", "at most")
    assert not (tmp_path / "o").exists() and not (tmp_path / "results").exists()


def test_a_sweep_starts_no_more_processes_than_it_has_tasks(tmp_path, monkeypatch):
    """`--workers 16` for 2 runs forked 16 processes (and with 100 000, hung forking): a pool is never
    larger than the runs it has to run."""
    from contextlib import contextmanager

    from infomarket.runner import execute, sweep

    asked = []

    @contextmanager
    def recording(workers):
        asked.append(workers)
        yield execute.InlineExecutor()

    monkeypatch.setattr(sweep, "local_executor", recording)
    assert main(["run", "fig2B", "--runs", "2", "--steps", "10", "--workers", "16", "--out", str(tmp_path / "o"),
                 "--quiet"]) == 0
    assert asked and max(asked) <= 2


@pytest.mark.parametrize("robots", ["10001", "100000", str(10**12)])
def test_chain_demo_refuses_a_swarm_beyond_its_memory_before_simulating(robots, capsys, monkeypatch):
    pytest.importorskip("infomarket.evm.evm_replay")  # the chain extra
    import infomarket

    monkeypatch.setattr(infomarket, "simulate", never)
    refused(capsys, ["chain", "demo", "--robots", robots, "--steps", "10"], "--robots", "at most")


# ------------------------------------------------------------------ scheduler addresses
BAD_ADDRESSES = ["tcp://", "tcp://head:99999", "tcp://head:port", "http://head:8786", "::::", "tcp://he ad:8786",
                 "tcp://[::1", "tcp://head:8786:1", "tcp:/head:8786", "\x1b[31m", "inproc://head", "inproc://head/1/x"]


@pytest.mark.parametrize("address", BAD_ADDRESSES)
@pytest.mark.parametrize("argv, option", [(["sweep", "fig2B", "--out", "o"], "--scheduler"),
                                          (["reproduce", "paper", "--out", "o"], "--scheduler"),
                                          (["attack-search", "attack_search", "--out", "o"], "--dask"),
                                          (["defence-search", "attack_search", "--out", "o"], "--dask")])
def test_a_malformed_scheduler_address_is_refused_before_work(argv, option, address, capsys, tmp_path, monkeypatch):
    from infomarket.runner import sweep

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sweep, "run_sweep", never)
    line = refused(capsys, [*argv, option, address], option)
    assert "\x1b" not in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("address", ["tcp://head:8786", "head:8786", "tls://10.0.0.1:8786", "tcp://[::1]:8786",
                                     "ws://scheduler.example.org:80", "inproc://192.0.2.2/23131/1"])
def test_well_formed_scheduler_addresses_pass_the_check(address):
    from infomarket.cliargs import scheduler_address

    assert scheduler_address(address) == address


@pytest.mark.parametrize("dask", [["--dask-local", "1"], ["--scheduler", "tcp://head:8786"]])
def test_workers_and_a_dask_cluster_together_are_refused(dask, capsys, tmp_path, monkeypatch):
    from infomarket.runner import sweep

    monkeypatch.setattr(sweep, "run_sweep", never)
    refused(capsys, ["sweep", "fig2B", "--out", str(tmp_path / "o"), "--workers", "2", *dask], "--workers", dask[0])
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------ smaller option checks
@pytest.mark.parametrize("argv", [["run", "fig2B", "--out", ""], ["sweep", "fig2B", "--out", " "],
                                  ["figures", "results", "--out", ""], ["replay", "fig2B", "--out", ""],
                                  ["attack-search", "attack_search", "--out", ""],
                                  ["sweep", "fig2B", "--out", "o", "--scheduler", ""]])
def test_an_empty_path_is_refused_not_taken_as_the_working_folder(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    refused(capsys, argv, "is empty")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("argv", [["attack-search", "attack_search", "--out", "o"],
                                  ["defence-search", "attack_search", "--out", "o"],
                                  ["rl-train", "--out", "o.json"], ["run", "fig2B"], ["sweep", "fig2B", "--out", "o"]])
@pytest.mark.parametrize("seed", [str(2**64), str(2**63), "-1"])
def test_every_seed_option_takes_the_same_63_bit_range(argv, seed, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    refused(capsys, [*argv, "--seed", seed], "--seed")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("other", [["--robots", "25"], ["--scaling"], ["--env"]])
def test_bench_many_with_another_bench_is_refused(other, capsys, monkeypatch):
    from infomarket import bench

    monkeypatch.setattr(bench, "run_bench", never)
    refused(capsys, ["bench", "--many", *other], "--many")


@pytest.mark.parametrize("budget, pairs", [("2", []), ("4", []), ("16", ["--pairs", "8"])])
def test_adaptive_attack_budget_below_one_generation_is_refused(budget, pairs, capsys, tmp_path):
    refused(capsys, ["adaptive-attack", "attack_search", "--defence", "staking", "--byzantines", "3",
                     "--budget", budget, *pairs, "--out", str(tmp_path / "a")], "--budget", "at least")
    assert not (tmp_path / "a").exists()


def test_the_sweeps_resume_hint_keeps_every_option_that_shapes_the_rerun(tmp_path):
    from infomarket.cli import build_parser
    from infomarket.runner.cli import _interrupted
    from infomarket.runner.plan import conditions
    from infomarket.config import load_experiment
    from infomarket.store import Store

    args = build_parser().parse_args(["sweep", "fig2B", "--out", str(tmp_path / "o"), "--workers", "2",
                                      "--runs", "3", "--events", "--retry-failed"])
    hint = _interrupted(Store(tmp_path / "o"), conditions(load_experiment("fig2B")), 3, args)
    assert hint.endswith(f"--out {tmp_path / 'o'} --runs 3 --workers 2 --events --retry-failed"), hint


def test_chain_study_without_the_studys_runs_is_refused_and_writes_nothing(tmp_path, capsys):
    assert main(["run", "fig2B", "--runs", "1", "--steps", "10", "--out", str(tmp_path / "s"), "--quiet"]) == 0
    refused(capsys, ["chain-study", str(tmp_path / "s"), "--out", str(tmp_path / "report")], "no runs")
    assert not (tmp_path / "report").exists()


def test_a_message_names_its_path_once(tmp_path, capsys):
    assert main(["run", "fig2B", "--runs", "1", "--steps", "10", "--out", str(tmp_path / "s"), "--quiet"]) == 0
    line = refused(capsys, ["sensitivity", str(tmp_path / "s"), "--out", str(tmp_path / "r")], "sampled design")
    assert line.count(str(tmp_path / "s")) == 1, line



def test_the_declared_seed_refusal_is_one_short_line_naming_the_seed_and_what_differs():
    """A reduced run with the study's declared seed is refused in one line of at most 160 characters (it ran to
    about 300): the seed, what differs by name, as many as fit and how many more.  (The search's own test
    checks the line the command prints.)"""
    from infomarket.analysis.study import seed_refusal

    reductions = ["2 of 8 cells", "--steps 1500 (declared 15000)", "--budget 4 (declared 96)", "--reduced"]
    assert seed_refusal(61001, reductions) == ("--seed 61001 is the declared study's own; this run differs in "
                                               "2 of 8 cells, --steps, --budget, --reduced: give another --seed")
    many = [f"--option-{i} {i} (declared {i + 1})" for i in range(20)]
    line = seed_refusal(2**63 - 1, ["1 of 8 cells", *many])
    assert line == (f"--seed {2**63 - 1} is the declared study's own; this run differs in 1 of 8 cells, "
                    "--option-0, --option-1, --option-2 and 17 more: give another --seed")
    assert len(line) == 76 + 12 + 3 * 12 + 12 + 21 == 157  # head, the cells, three options, how many more, tail
    assert len(seed_refusal(7, ["x" * 1000])) <= 160
