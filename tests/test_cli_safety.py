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
    import infomarket.runner.run
    import infomarket.runner.sweep

    def never(*a, **k):
        pytest.fail("started running instead of refusing")

    monkeypatch.setattr(infomarket.runner.run, "run_experiment", never)
    monkeypatch.setattr(infomarket.runner.sweep, "run_sweep", never)
    exp = write(tmp_path)
    out = tmp_path / "o"
    assert main(["run", str(exp), "--runs", "1000000000", "--out", str(out), "--quiet"]) == 2
    assert "--runs 1000000000: the results of 1,000,000,000 runs would need about" in capsys.readouterr().err
    assert main(["sweep", str(exp), "--runs", "1000000000", "--out", str(out), "--quiet"]) == 2
    assert "1,000,000,000 runs" in capsys.readouterr().err
    assert main(["run", str(write(tmp_path, robots=10**9)), "--out", str(out), "--quiet"]) == 2
    assert not out.exists()


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_run_refuses_to_replace_other_runs_without_force(tmp_path, capsys):
    from infomarket.store import Store

    exp, out = write(tmp_path), tmp_path / "o"
    assert main(["run", str(exp), "--runs", "1", "--out", str(out), "--quiet"]) == 0
    first = _files(out)
    # another configuration (300 -> 400 steps) or another master seed: refused, the store untouched
    for extra in (["--steps", "400"], ["--seed", "9"]):
        assert main(["run", str(exp), "--runs", "2", "--out", str(out), "--quiet", *extra]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"infomarket: error: --out {out}: holds runs of small made with ") and "--force" in err
        assert err.count("\n") == 1 and _files(out) == first
    assert "another configuration" in err or "master seed 1 (now 9)" in err
    assert main(["run", str(exp), "--runs", "2", "--out", str(out), "--quiet", "--steps", "400", "--force"]) == 0
    runs = Store(out).runs()
    assert sorted(runs.run) == [0, 1] and set(runs.steps) == {400}  # replaced, not mixed
    # the same request with more runs adds the missing runs and keeps the others byte for byte
    before = _files(out)
    assert main(["run", str(exp), "--runs", "3", "--out", str(out), "--quiet", "--steps", "400"]) == 0
    after = _files(out)
    assert {k: after[k] for k in before if k != "store.json"} == {k: v for k, v in before.items() if k != "store.json"}
    assert sorted(Store(out).runs().run) == [0, 1, 2]


def test_run_replaces_an_earlier_versions_flat_files_only_with_force(tmp_path, capsys):
    exp, out = write(tmp_path), tmp_path / "old"
    out.mkdir()
    (out / "robots.parquet").write_bytes(b"an earlier run's table")
    assert main(["run", str(exp), "--runs", "1", "--out", str(out), "--quiet"]) == 2
    assert "robots.parquet exists" in capsys.readouterr().err
    assert _files(out) == {"robots.parquet": b"an earlier run's table"}
    assert main(["run", str(exp), "--runs", "1", "--out", str(out), "--quiet", "--force"]) == 0
    assert not (out / "robots.parquet").exists() and (out / "store.json").exists()
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")  # anything else is never removed, even with --force
    assert main(["run", str(exp), "--runs", "1", "--out", str(tmp_path / "mine"), "--quiet", "--force"]) == 2
    assert "not an infomarket results store" in capsys.readouterr().err
    assert _files(tmp_path / "mine") == {"notes.txt": b"keep"}


def test_an_interrupted_run_keeps_the_runs_it_finished_and_resumes(tmp_path, capsys, monkeypatch):
    from infomarket.runner import execute
    from infomarket.store import Store

    real = execute.run_one

    def one(cfg, run, *args, **kw):
        if run == 2:
            raise KeyboardInterrupt  # Ctrl-C during the third run
        return real(cfg, run, *args, **kw)

    monkeypatch.setattr(execute, "run_one", one)
    out = tmp_path / "o"
    argv = ["run", str(write(tmp_path)), "--runs", "3", "--workers", "1", "--out", str(out), "--quiet"]
    assert main(argv) == 130
    assert "kept the 2 of 3 runs that had finished" in capsys.readouterr().err
    kept = Store(out).robots()
    assert sorted(kept.run.unique()) == [0, 1]
    assert main(["store", "verify", str(out)]) == 0
    monkeypatch.setattr(execute, "run_one", real)
    assert main(argv) == 0  # resumes: runs only run 2
    robots = Store(out).robots()
    assert sorted(robots.run.unique()) == [0, 1, 2]
    pd.testing.assert_frame_equal(robots[robots.run < 2].reset_index(drop=True), kept, check_exact=True)


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
