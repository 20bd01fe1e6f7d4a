"""Hostile conditions by family, beyond the inputs themselves: the operating system refusing a write (a
full disk, a read-only folder, a name too long, a file where a store's folder must be), the Python API
given values of the wrong kind, a stop in the middle of writing a file, and the documented sequences and
examples.  The command line ends each in one ``infomarket: error:`` line and exit 2, with what was
committed before intact and no half-written file; the API raises an error naming the argument."""
from __future__ import annotations

import copy
import errno
import os
import pickle
import re
from pathlib import Path

import numpy as np
import pytest

from infomarket.cli import main
from infomarket.config import sizes
from infomarket.errors import InfomarketError
from .refusals import refused, never

ROOT = Path(__file__).parents[1]


@pytest.fixture(autouse=True)
def limit(monkeypatch):
    monkeypatch.setenv(sizes.ENV, "16GiB")


@pytest.fixture(scope="module")
def fig2b():
    from infomarket.config import load_experiment

    return load_experiment("fig2B").with_overrides(steps=200)


def small_store(folder: Path, runs: int = 1) -> Path:
    assert main(["run", "fig2B", "--runs", str(runs), "--steps", "10", "--out", str(folder), "--quiet"]) == 0
    return folder


class _FailingOs:
    """``os`` whose ``replace`` (the atomic rename every file write ends with) fails with ``code``."""

    def __init__(self, code: int):
        self.code = code

    def __getattr__(self, name):
        return getattr(os, name)

    def replace(self, src, dst):
        raise OSError(self.code, os.strerror(self.code), str(dst))


# ------------------------------------------------------------------ the operating system refuses a write
@pytest.mark.parametrize("code, words", [(errno.ENOSPC, "No space left"), (errno.EROFS, "Read-only"),
                                         (errno.EACCES, "Permission denied"), (errno.EDQUOT, "quota"),
                                         (errno.EIO, "Input/output")])
def test_a_write_the_system_refuses_is_one_message_and_keeps_what_was_committed(code, words, tmp_path, capsys,
                                                                                monkeypatch):
    from infomarket.store import Store, files

    out = small_store(tmp_path / "st")
    before = sorted(p.name for p in out.rglob("*"))
    monkeypatch.setattr(files, "os", _FailingOs(code))
    refused(capsys, ["run", "fig2B", "--runs", "3", "--steps", "10", "--out", str(out), "--quiet"], words)
    monkeypatch.undo()
    monkeypatch.setenv(sizes.ENV, "16GiB")
    assert sorted(p.name for p in out.rglob("*")) == before  # no temporary or half-written file left
    found = Store(out).verify()
    assert found.parts == 1 and not found.damaged and not found.orphans


@pytest.mark.parametrize("argv", [["run", "fig2B", "--runs", "1", "--steps", "10", "--out"],
                                  ["sweep", "fig2B", "--runs", "1", "--out"],
                                  ["replay", "fig2B", "--steps", "20", "--out"]])
def test_a_name_too_long_for_the_file_system_is_one_message(argv, tmp_path, capsys):
    long = str(tmp_path / ("x" * 300)) + ("" if argv[0] != "replay" else ".html")
    refused(capsys, [*argv, long], "too long")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("table", ["robots", "runs", "history", "configs"])
@pytest.mark.parametrize("argv", [["store", "verify", "{}"], ["store", "sql", "{}", "SELECT count(*) FROM robots"],
                                  ["run", "fig2B", "--runs", "2", "--steps", "10", "--out", "{}"]])
def test_a_store_whose_table_folder_is_a_file_is_one_message(table, argv, tmp_path, capsys):
    if "sql" in argv:
        pytest.importorskip("duckdb")
    out = small_store(tmp_path / "st")
    folder = out / table
    if folder.is_dir():
        for f in folder.iterdir():
            f.unlink()
        folder.rmdir()
    folder.write_text("not a folder")
    argv = [str(out) if a == "{}" else a for a in argv]
    refused(capsys, argv, str(out))
    assert folder.read_text() == "not a folder"


def test_rl_train_checks_its_out_before_training(tmp_path, capsys, monkeypatch):
    pytest.importorskip("gymnasium")
    import tempfile

    from infomarket.rl import train

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(train, "train", never)
    monkeypatch.setattr(tempfile, "TemporaryFile", read_only)
    refused(capsys, ["rl-train", "--steps", "60", "--transitory", "20", "--iterations", "1", "--pairs", "1",
                     "--out", str(tmp_path / "r.json")], "--out", "Read-only")


@pytest.mark.parametrize("option, name", [("--out", "r.html"), ("--movie", "r.gif")])
@pytest.mark.parametrize("where, words", [("read-only", ["Read-only"]), ("under a file", ["not a folder"]),
                                          ("a folder", ["is a directory"])])
def test_replay_checks_its_files_before_recording(option, name, where, words, tmp_path, capsys, monkeypatch):
    """Each file replay writes is checked before the run is recorded, and named for what is wrong with it."""
    import tempfile

    from infomarket.viewer import recording

    target = tmp_path / name
    if where == "read-only":
        def read_only(*args, **kwargs):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))

        monkeypatch.setattr(tempfile, "TemporaryFile", read_only)
    elif where == "under a file":
        (tmp_path / "file").write_text("x")
        target = tmp_path / "file" / name
    else:
        target.mkdir()
    monkeypatch.setattr(recording, "record", never)
    refused(capsys, ["replay", "fig2B", "--steps", "20", option, str(target)], option, str(target), *words)


# ------------------------------------------------------------------ the Python API: arguments named
@pytest.mark.parametrize("steps", [-5, "x", 0, 2.5, True, 10**30, 2**63, [10]])
def test_simulate_names_steps(steps, fig2b):
    from infomarket import simulate

    with pytest.raises(InfomarketError, match="steps"):
        simulate(fig2b, 1, steps=steps)


def test_a_simulation_pickled_or_deep_copied_goes_on_as_the_original(fig2b):
    from infomarket.engine.simulation import Simulation

    sim = Simulation(fig2b.with_overrides(steps=400), 3)
    sim.step(150)
    copies = [pickle.loads(pickle.dumps(sim)), copy.deepcopy(sim)]
    for s in (sim, *copies):
        s.step(200)
    for c in copies:
        assert c.clock == sim.clock == 350
        assert np.array_equal(c.world.pos, sim.world.pos) and np.array_equal(c.world.bias, sim.world.bias)
    results = [s.run() for s in (sim, *copies)]
    for r in results[1:]:
        assert r.robots.equals(results[0].robots)


@pytest.mark.parametrize("seed", ["a", 2**64, -1, 1.5, True, b"1", ["a", 1], [2**64, 0], [0]])
def test_the_rl_envs_name_a_bad_seed(seed):
    pytest.importorskip("gymnasium")
    from infomarket.rl import AttackVectorEnv

    venv = AttackVectorEnv(num_envs=2, steps=60, transitory=20, interval=10)
    with pytest.raises(InfomarketError, match="seed"):
        venv.reset(seed=seed)


@pytest.mark.parametrize("seed", ["a", 2**64, -1, 1.5])
def test_the_single_env_names_a_bad_seed(seed):
    pytest.importorskip("gymnasium")
    from infomarket.rl import AttackEnv

    with pytest.raises(InfomarketError, match="seed"):
        AttackEnv(steps=60, transitory=20, interval=10).reset(seed=seed)


# ------------------------------------------------------------------ a stop while a file is written
@pytest.mark.parametrize("stop", [KeyboardInterrupt, lambda: OSError(errno.ENOSPC, "No space left on device")])
@pytest.mark.parametrize("suffix", [".gif", ".html"])
def test_a_stopped_replay_leaves_no_part_file(stop, suffix, fig2b, tmp_path, monkeypatch):
    from infomarket.viewer import movie, recording

    rec = recording.record(fig2b, 1, steps=60, every=10)
    if suffix == ".gif":
        from matplotlib import animation

        calls = []
        grab = animation.PillowWriter.grab_frame

        def stopping(self, **kw):
            calls.append(1)
            if len(calls) == 3:
                raise stop()
            return grab(self, **kw)

        monkeypatch.setattr(animation.PillowWriter, "grab_frame", stopping)
        write = movie.write_movie
    else:
        monkeypatch.setattr(recording, "html", lambda rec: (_ for _ in ()).throw(stop()))
        write = recording.write_html
    with pytest.raises((KeyboardInterrupt, OSError)):
        write(rec, tmp_path / f"x{suffix}")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ documented sequences and examples
def test_no_docs_python_example_imports_the_test_suite():
    """A user's Python has the package, not the repository's tests/: every example imports only what an
    installed infomarket (and its extras) gives."""
    for doc in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for block in re.findall(r"```python\n(.*?)```", doc.read_text(), re.S):
            assert not re.search(r"^\s*(from|import)\s+tests\b", block, re.M), f"{doc.name} imports tests.*"


def test_terrain_report_on_a_store_made_by_run_names_the_sweep_it_needs(tmp_path):
    from infomarket.analysis import terrain
    from infomarket.cliargs import UsageError

    assert main(["run", "two_food", "--runs", "1", "--steps", "20", "--out", str(tmp_path / "two_food"),
                 "--quiet"]) == 0
    with pytest.raises(UsageError, match="infomarket sweep two_food"):
        terrain._robots(tmp_path, "two_food", "food_sites")  # what answer() reads for the two-food question
