"""One writer, one seed: a store is locked while a sweep writes it, and records its master seed."""
import json
import os
import signal
import subprocess
import sys

from infomarket.cli import main
from infomarket.store import Store

SWEEP = ["--workers", "1", "--quiet"]
HOLD = """
import sys
from infomarket.store import Store
s = Store(sys.argv[1]).create()
with s.lock():
    print("locked", flush=True)
    sys.stdin.read()  # until the test closes it, or kills this process
"""


def sweep(exp, out, *extra):
    return main(["sweep", str(exp), "--out", str(out), *SWEEP, *extra])


def hold_lock(procs, out):
    """A separate process holding the store's lock, as a sweep does while it writes."""
    proc = procs.start([sys.executable, "-c", HOLD, str(out)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                       text=True)
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_a_second_writer_is_refused_and_a_killed_ones_lock_dies_with_it(tiny, tmp_path, capsys, procs):
    out = tmp_path / "s"
    holder = hold_lock(procs, out)
    try:
        assert sweep(tiny(), out) == 2
        assert "another infomarket process is writing this store" in capsys.readouterr().err
        assert Store(out).runs().empty
    finally:
        os.kill(holder.pid, signal.SIGKILL)
        holder.wait()
    assert sweep(tiny(), out) == 0  # at once: no stale lock after SIGKILL
    assert len(Store(out).runs()) == 6


def test_another_seed_is_refused_and_the_seed_is_recorded(tiny, tmp_path, capsys):
    out = tmp_path / "s"
    assert sweep(tiny(seed=1), out) == 0
    assert json.loads((out / "store.json").read_text())["seeds"] == {"tiny": 1}
    assert set(Store(out).runs().master_seed) == {1}
    for extra in (["--seed", "2"], ["--seed", "2", "--runs", "5"]):
        assert sweep(tiny(seed=1), out, *extra) == 2
        err = capsys.readouterr().err
        assert "master seed 1" in err and "start a new store (another --out)" in err
    assert sweep(tiny(seed=2, runs=5), out) == 2  # the file's own seed changed: refused too
    capsys.readouterr()
    runs = Store(out).runs()
    assert len(runs) == 6
    assert sweep(tiny(seed=1), out, "--runs", "4") == 0  # the same seed resumes and extends
    assert len(Store(out).runs()) == 8


def test_a_store_made_before_seeds_were_recorded_is_still_checked(tiny, tmp_path, capsys):
    out = tmp_path / "s"
    assert sweep(tiny(seed=1), out) == 0
    meta = json.loads((out / "store.json").read_text())
    del meta["seeds"]
    (out / "store.json").write_text(json.dumps(meta))
    assert sweep(tiny(seed=1), out, "--seed", "2", "--runs", "5") == 2
    assert "another master seed" in capsys.readouterr().err
    assert len(Store(out).runs()) == 6
