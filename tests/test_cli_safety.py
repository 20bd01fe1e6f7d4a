"""Sizes checked before memory is spent, outputs checked before time is spent, nothing silently lost,
--quiet means quiet, and every error in one style (``infomarket: error: ...``, exit 2, no traceback)."""
import os
import tempfile
from pathlib import Path

import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.config import sizes

SMALL = """
name = "small"
steps = {steps}
runs = 3
seed = 1

[swarm]
robots = {robots}

[[swarm.groups]]
behaviour = "naive"
count = {robots}
"""


def write(tmp_path, steps=300, robots=5) -> Path:
    p = tmp_path / "small.toml"
    p.write_text(SMALL.format(steps=steps, robots=robots))
    return p


@pytest.fixture(autouse=True)
def limit(monkeypatch):
    monkeypatch.setenv(sizes.ENV, "16GiB")  # the same limit on every machine


def test_too_many_robots_or_steps_are_refused_by_check_with_the_estimate(tmp_path, capsys, monkeypatch):
    assert main(["check", str(write(tmp_path, robots=10**9))]) == 2
    err = capsys.readouterr().err
    assert "one run would need about" in err and "INFOMARKET_MEMORY_LIMIT=" in err and "limit of 16.0 GiB" in err
    # 16 bytes x (10**12 + 1) entries = 1.6e13 bytes = 14.55 TiB (by hand)
    assert main(["check", str(write(tmp_path, steps=10**12))]) == 2
    assert "Lévy step-length table 14.6 TiB" in capsys.readouterr().err
    monkeypatch.setenv(sizes.ENV, "20TiB")  # raised deliberately: valid
    assert main(["check", str(write(tmp_path, steps=10**12))]) == 0


def test_run_and_sweep_refuse_too_many_runs_at_once_and_write_nothing(tmp_path, capsys, monkeypatch):
    import infomarket.runner
    import infomarket.runner.sweep

    never = lambda *a, **k: pytest.fail("started running instead of refusing")  # noqa: E731
    monkeypatch.setattr(infomarket.runner, "run_batch", never)
    monkeypatch.setattr(infomarket.runner.sweep, "run_sweep", never)
    exp = write(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(exp), "--runs", "1000000000", "--out", str(out), "--quiet"]) == 2
    assert "--runs 1000000000: the results of 1,000,000,000 runs would need about" in capsys.readouterr().err
    assert main(["sweep", str(exp), "--runs", "1000000000", "--out", str(out), "--quiet"]) == 2
    assert "1,000,000,000 runs" in capsys.readouterr().err
    assert main(["run", str(write(tmp_path, robots=10**9)), "--out", str(out), "--quiet"]) == 2
    assert not out.exists()


def test_run_refuses_to_overwrite_without_force(tmp_path, capsys):
    exp, out = write(tmp_path), tmp_path / "o"
    assert main(["run", str(exp), "--runs", "1", "--out", str(out), "--quiet"]) == 0
    first = (out / "robots.parquet").read_bytes()
    assert main(["run", str(exp), "--runs", "2", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "robots.parquet exists" in err and "--force replaces it" in err
    assert (out / "robots.parquet").read_bytes() == first
    assert main(["run", str(exp), "--runs", "2", "--out", str(out), "--quiet", "--force"]) == 0
    assert pd.read_parquet(out / "robots.parquet").run.nunique() == 2


def test_an_interrupted_run_keeps_the_runs_it_finished(tmp_path, capsys, monkeypatch):
    from infomarket.runner import batch

    real = batch._one

    def one(cfg, run, *args, **kw):
        if run == 2:
            raise KeyboardInterrupt  # Ctrl-C during the third run
        return real(cfg, run, *args, **kw)

    monkeypatch.setattr(batch, "_one", one)
    out = tmp_path / "o"
    assert main(["run", str(write(tmp_path)), "--runs", "3", "--workers", "1", "--out", str(out),
                 "--quiet"]) == 130
    assert "kept the 2 of 3 runs that had finished" in capsys.readouterr().err
    assert sorted(pd.read_parquet(out / "robots.parquet").run.unique()) == [0, 1]


def test_quiet_prints_nothing(tmp_path, capsys):
    exp = write(tmp_path)
    assert main(["run", str(exp), "--runs", "2", "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert main(["sweep", str(exp), "--out", str(tmp_path / "s"), "--workers", "1", "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")


def read_only_folder(tmp_path) -> Path:
    if os.geteuid() != 0:
        folder = tmp_path / "ro"
        folder.mkdir()
        folder.chmod(0o555)
        return folder
    try:  # root writes anywhere a mode allows nothing; sysfs refuses even root
        tempfile.TemporaryFile(dir="/sys").close()
    except OSError:
        return Path("/sys")
    pytest.skip("no folder here refuses writes")


def test_replay_into_a_read_only_folder_fails_before_simulating(tmp_path, capsys, monkeypatch):
    from infomarket.viewer import recording

    monkeypatch.setattr(recording, "record", lambda *a, **k: pytest.fail("simulated before checking --out"))
    out = read_only_folder(tmp_path) / "run.html"
    assert main(["replay", "fig2B", "--steps", "50", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"infomarket: error: --out {out}: cannot write there") and "Traceback" not in err


def test_every_error_has_one_style_and_one_path_style(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "fig2A", "--runs", "x"])
    assert exc.value.code == 2
    assert "infomarket: error: infomarket run: argument --runs: expected an integer" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text('[swarm]\nrobots = 2\ngroups = [{behaviour = "naive", count = "two"}]\n')
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "swarm.groups[0].count: Input should be a valid integer" in err and "groups.0" not in err
    assert main(["figures", str(tmp_path / "nothing"), "--out", str(tmp_path / "f")]) == 2
    assert capsys.readouterr().err.startswith("infomarket: error: ")
