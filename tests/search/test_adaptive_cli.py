"""``infomarket adaptive-attack``: bad input is one error line and exit 2 with nothing written; a tiny
training writes its policy and summaries; stopped by Ctrl-C it keeps its checkpoint, and the same command
again resumes to the policy an uninterrupted training gives."""
import json
import signal
import subprocess
import time

import numpy as np
import pytest

from infomarket.cli import main
from infomarket.config import sizes
from infomarket.search.adaptive import CHECKPOINT, Policy, resumed_generations
from infomarket.search.adaptive_cli import POLICY_FILE, SUMMARY_JSON, SUMMARY_MD

from ..procs import HANG
from ..refusals import ERROR, refused

CELL = ["adaptive-attack", "attack_search", "--defence", "staking", "--byzantines", "3"]
TINY = CELL + ["--budget", "10", "--pairs", "2", "--runs", "1", "--steps", "1000", "--transitory", "0",
               "--eval-runs", "2", "--seed", "3"]


@pytest.fixture(autouse=True)
def limit(monkeypatch):
    monkeypatch.setenv(sizes.ENV, "16GiB")  # the same memory limit on every machine


@pytest.mark.parametrize("extra, words", [
    (["--defence", "moat", "--byzantines", "3", "--budget", "5"], ["--defence moat", "allowed"]),
    (["--defence", "staking", "--byzantines", "4", "--budget", "5"], ["--byzantines 4", "allowed"]),
    (["--defence", " ", "--byzantines", "3", "--budget", "5"], ["--defence"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "0"], ["--budget", ">= 1"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "5", "--sigma", "inf"], ["--sigma", "finite"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "5", "--steps", "100", "--transitory", "100"],
     ["--transitory 100", "below --steps 100"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "5", "--transitory", "40000"], ["--transitory 40000"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "5", "--objective", "gold"], ["--objective"]),
    (["--defence", "staking", "--byzantines", "3", "--budget", "5", "--seed", "-1"], ["--seed"]),
    # a budget of at least one generation (1 + 2 x pairs), so the memory check is what refuses it
    (["--defence", "staking", "--byzantines", "3", "--budget", "300000000", "--pairs", "100000000", "--runs", "1000"],
     ["200000001 candidates x 1000 runs", "memory"]),
])
def test_bad_input_is_one_error_and_nothing_written(extra, words, tmp_path, capsys):
    out = tmp_path / "out"
    refused(capsys, ["adaptive-attack", "attack_search", *extra, "--out", str(out)], *words)
    assert not out.exists()


def test_an_out_that_is_a_file_or_blank_is_refused(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("keep")
    refused(capsys, CELL + ["--budget", "5", "--out", str(f)], "not a directory")
    assert f.read_text() == "keep"
    refused(capsys, CELL + ["--budget", "5", "--out", " "], "--out")


def test_an_unknown_experiment_is_refused(tmp_path, capsys):
    refused(capsys, ["adaptive-attack", "no_such_experiment", "--defence", "staking", "--byzantines", "3",
                     "--budget", "5", "--out", str(tmp_path / "o")], "no_such_experiment")


def test_a_checkpoint_of_other_settings_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(TINY + ["--quiet", "--out", str(out)]) == 0
    before = (out / CHECKPOINT).read_bytes()
    refused(capsys, [*TINY[:-1], "4", "--quiet", "--out", str(out)], "a checkpoint of another training")
    assert (out / CHECKPOINT).read_bytes() == before


def test_a_tiny_training_writes_its_policy_and_summaries(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(TINY + ["--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / SUMMARY_JSON).read_text())
    assert summary["generations"] == 2 and summary["runs_played"] == 2 * 5 * 1
    assert len(summary["curve"]) == 2 and summary["evaluation"]["runs"] == 2
    policy = Policy.load(out / POLICY_FILE)
    assert policy.info["curve"] == summary["curve"] and policy.at_rest() == summary["policy_at_rest"]
    assert "Adaptive attacker" in (out / SUMMARY_MD).read_text() and "Adaptive attacker" in printed
    # the same command again finds every generation done and writes the same policy
    assert main(TINY + ["--quiet", "--out", str(out)]) == 0
    np.testing.assert_array_equal(Policy.load(out / POLICY_FILE).weights, policy.weights)


def test_ctrl_c_keeps_the_checkpoint_and_the_same_command_resumes_to_the_same_policy(tmp_path, procs):
    longer = TINY[:TINY.index("--budget")] + ["--budget", "100", "--pairs", "2", "--runs", "1", "--steps", "2000",
                                             "--transitory", "0", "--eval-runs", "0", "--seed", "3"]
    whole = tmp_path / "whole"
    assert main(longer + ["--quiet", "--out", str(whole)]) == 0
    out = tmp_path / "stopped"
    proc = procs.cli(*longer, "--quiet", "--out", out, env={"INFOMARKET_COMPILE_NOTICE": "0"},
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + HANG
    while time.monotonic() < deadline and proc.poll() is None and not (out / CHECKPOINT).exists():
        time.sleep(0.02)
    assert (out / CHECKPOINT).exists(), "no checkpoint written after a generation"
    proc.send_signal(signal.SIGINT)
    err = proc.communicate(timeout=HANG)[1].decode()
    if proc.returncode == 0 and resumed_generations(out) == 20:
        pytest.skip("the training finished before the signal came")
    assert proc.returncode == 130, err
    assert err.count(ERROR) == 1 and "interrupted" in err and "Traceback" not in err, err
    assert not (out / POLICY_FILE).exists() and (out / CHECKPOINT).exists()
    assert main(longer + ["--quiet", "--out", str(out)]) == 0
    np.testing.assert_array_equal(Policy.load(out / POLICY_FILE).weights, Policy.load(whole / POLICY_FILE).weights)
