"""``infomarket.interrupts``: a stop is never lost, a compile in a child is killed at once, and ``store sql``
stops on Ctrl-C in the middle of a query (a library's blocking call left at once: ``wait_for``)."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from infomarket import interrupts

from .analysis.synthetic import paper_like, write_store
from .procs import HANG, catches, session_members


def _signal_when(event: threading.Event, sig=signal.SIGINT) -> threading.Thread:
    """A thread that sends ``sig`` to this process once ``event`` is set."""
    def send():
        if event.wait(HANG):
            os.kill(os.getpid(), sig)

    t = threading.Thread(target=send, daemon=True)
    t.start()
    return t


def test_a_stop_is_sticky_and_handling_puts_the_handlers_back():
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    with interrupts.handling() as stop:
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(HANG)  # interrupted by the handler's KeyboardInterrupt
        except KeyboardInterrupt:
            pass  # swallowed, as a finalizer would
        assert interrupts.requested() == signal.SIGTERM and interrupts.exit_code() == 143
        with pytest.raises(KeyboardInterrupt):
            interrupts.check()  # raised again at the next safe point
        with pytest.raises(KeyboardInterrupt):
            interrupts.check()
    assert stop.signum == signal.SIGTERM
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
    interrupts.check()  # outside a command nothing is pending
    assert interrupts.requested() == 0 and interrupts.exit_code() == 130


def test_a_compile_in_a_child_is_killed_at_once_and_a_finished_one_is_loaded_here(tmp_path):
    """The child blocks for ever where a compile would run for a minute: a signal to the command kills
    it (it is reaped, no marker); a child that finishes leaves the marker, and the call then runs here."""
    parent = os.getpid()
    calls = tmp_path / "calls"
    calls.mkdir()
    child_started = threading.Event()

    def compile_forever():
        (calls / str(os.getpid())).touch()
        if os.getpid() != parent:
            while True:
                time.sleep(1)
        return "here"

    def watch():
        deadline = time.monotonic() + HANG
        while not [p for p in calls.iterdir() if int(p.name) != parent] and time.monotonic() < deadline:
            time.sleep(0.01)
        child_started.set()

    threading.Thread(target=watch, daemon=True).start()
    _signal_when(child_started)
    marker = tmp_path / "kernel.simulation.compiled"
    try:
        with interrupts.handling(), pytest.raises(KeyboardInterrupt):
            interrupts.compiled_apart(compile_forever, marker)
        child = int(next(p.name for p in calls.iterdir()))
        assert child != parent and not Path(f"/proc/{child}").exists()  # killed and reaped
        assert not marker.exists()
    finally:
        for p in calls.iterdir():
            if int(p.name) != parent and Path(f"/proc/{p.name}").exists():
                os.kill(int(p.name), signal.SIGKILL)

    for p in calls.iterdir():
        p.unlink()
    with interrupts.handling():
        assert interrupts.compiled_apart(lambda: (calls / str(os.getpid())).touch() or "loaded", marker) == "loaded"
        assert marker.exists() and len(list(calls.iterdir())) == 2  # the child's call, then this one
        for p in calls.iterdir():
            p.unlink()
        assert interrupts.compiled_apart(lambda: (calls / str(os.getpid())).touch() or "again", marker) == "again"
        assert [p.name for p in calls.iterdir()] == [str(parent)]  # marked: no child any more
    assert interrupts.compiled_apart(lambda: "plain", None) == "plain"  # outside a command: just the call



def test_kernels_compiled_together_share_one_child_and_are_then_loaded_here(tmp_path):
    """A command's new kernels are compiled in one child (which types the step's helpers once for all of
    them), each leaving its marker; the calls here then load them without another child.  Outside a
    command, or with every marker there, nothing is forked."""
    parent = os.getpid()
    calls = tmp_path / "calls"
    calls.mkdir()
    markers = [tmp_path / f"kernel{k}.simulation.compiled" for k in range(3)]

    def compile_(k):
        return lambda: (calls / f"{k}-{os.getpid()}").touch() or f"kernel {k}"

    def each():
        return [interrupts.compiled_apart(compile_(k), m) for k, m in enumerate(markers)]

    interrupts.compiled_together(each, markers)  # outside a command: nothing
    assert not list(calls.iterdir())
    with interrupts.handling():
        interrupts.compiled_together(each, markers)
        seen = [p.name.split("-") for p in calls.iterdir()]
        assert sorted(k for k, _ in seen) == ["0", "1", "2"] and len({pid for _, pid in seen}) == 1
        child = int(seen[0][1])
        assert child != parent and not Path(f"/proc/{child}").exists()  # one child, reaped
        assert all(m.exists() for m in markers)
        for p in calls.iterdir():
            p.unlink()
        assert each() == ["kernel 0", "kernel 1", "kernel 2"]
        assert sorted(p.name for p in calls.iterdir()) == [f"{k}-{parent}" for k in range(3)]  # loaded here
        for p in calls.iterdir():
            p.unlink()
        interrupts.compiled_together(each, markers)  # every marker there: no child
        assert not list(calls.iterdir())


def test_a_stop_while_kernels_compile_together_kills_their_child_at_once(tmp_path):
    parent = os.getpid()
    started = tmp_path / "started"
    marker = tmp_path / "kernel.simulation.compiled"
    child_started = threading.Event()

    def forever():
        (tmp_path / "pid").write_text(str(os.getpid()))
        os.replace(tmp_path / "pid", started)  # whole, or not there: the watcher never reads half of it
        while True:
            time.sleep(1)

    def watch():
        deadline = time.monotonic() + HANG
        while not started.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        child_started.set()

    threading.Thread(target=watch, daemon=True).start()
    _signal_when(child_started)
    try:
        with interrupts.handling(), pytest.raises(KeyboardInterrupt):
            interrupts.compiled_together(lambda: interrupts.compiled_apart(forever, marker), [marker])
        child = int(started.read_text())
        assert child != parent and not Path(f"/proc/{child}").exists() and not marker.exists()
    finally:
        if started.exists() and Path(f"/proc/{started.read_text()}").exists():
            os.kill(int(started.read_text()), signal.SIGKILL)


class _Unpicklable(ValueError):
    def __reduce__(self):
        raise TypeError("not picklable")


def test_a_compile_that_fails_in_the_child_is_raised_here_without_compiling_again(tmp_path):
    """A failed compile is not cached, so compiling it again here would pay it twice: the child's error is
    raised here.  One the child cannot hand over is met by running the call here, as before."""
    parent, marker = os.getpid(), tmp_path / "kernel.simulation.compiled"

    def failing(error):
        def compile_():
            (tmp_path / str(os.getpid())).touch()
            raise error("rule three_values_sell returns 3 values")
        return compile_

    with interrupts.handling(), pytest.raises(ValueError, match="returns 3 values"):
        interrupts.compiled_apart(failing(ValueError), marker)
    calls = [int(p.name) for p in tmp_path.iterdir() if p.suffix != ".lock"]  # the kernel's lock beside them
    assert len(calls) == 1 and calls[0] != parent and not marker.exists()  # the child's compile only
    (tmp_path / str(calls[0])).unlink()
    with interrupts.handling(), pytest.raises(_Unpicklable, match="returns 3 values"):
        interrupts.compiled_apart(failing(_Unpicklable), marker)
    assert parent in [int(p.name) for p in tmp_path.iterdir() if p.suffix != ".lock"] and not marker.exists()


def _threads(pid: int) -> int:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0
    return int(next(line.split()[1] for line in status.splitlines() if line.startswith("Threads:")))


def test_ctrl_c_stops_store_sql_in_the_middle_of_a_query(tmp_path, procs):
    store = write_store(tmp_path / "s", paper_like(), only=("fig2A",))
    endless = "SELECT sum(a.range * b.range) FROM range(1000000000) a, range(1000000000) b"
    proc = procs.cli("store", "sql", store.root, endless, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + HANG
    while not (catches(proc.pid, signal.SIGTERM) and _threads(proc.pid) > 3) and proc.poll() is None \
            and time.monotonic() < deadline:
        time.sleep(0.01)  # until the command has started and DuckDB's threads are there; the query never ends
    assert proc.poll() is None, proc.communicate()
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=HANG)
    assert proc.returncode == 130, err
    assert err == "infomarket: error: interrupted\n" and out == ""
    assert session_members(proc.pid) == []


# A command that holds a stop signal across a fork: the signal is sent (to this thread, so that it stays
# pending under the block whatever other threads exist) before the fork, as a Ctrl-C landing inside
# ``os.fork`` would be.  Another library's at-fork hook, registered after infomarket's, runs after it
# inside the same fork (``logging`` has one, for instance): the stop must not be let through there either.
_FORK_SCRIPT = """
import os, signal, sys, threading
from infomarket import interrupts

def other_hook():
    len(())  # a call: an event the profile function sees, inside the fork

os.register_at_fork(after_in_parent=other_hook)

def profile(frame, event, arg):
    pass

def fork():
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    return pid

with interrupts.handling():
    sys.setprofile(profile)
    os.waitpid(fork(), 0)  # nothing pending: signals let through again, the profile function put back
    print(sorted(signal.pthread_sigmask(signal.SIG_BLOCK, set())), sys.getprofile() is profile)
    sys.setprofile(None)
    try:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIG%s})
        signal.pthread_kill(threading.main_thread().ident, signal.SIG%s)
        fork()
        print("not stopped")
    except KeyboardInterrupt:
        print("stopped", interrupts.requested())
    print(sorted(signal.pthread_sigmask(signal.SIG_BLOCK, set())))
"""


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_held_across_a_fork_is_raised_after_the_fork_not_dropped_in_its_hook(procs, sig):
    """Let through inside the at-fork hook that ends a held fork, the stop's ``KeyboardInterrupt`` would
    be raised there, where Python drops it ("Exception ignored in ...") and the command runs on; it must
    reach the code that called ``os.fork``.  In a process of its own: a real fork, one thread."""
    name = signal.Signals(sig).name[3:]
    done = procs.run([sys.executable, "-c", _FORK_SCRIPT % (name, name)])
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert done.stdout == f"[] True\nstopped {int(sig)}\n[]\n"


# The console script's own two lines (pyproject's [project.scripts]), after a finder that stops the start-up
# in the middle of the imports, just before the module named on its command line is imported, and says so.
_START_SCRIPT = f"""
import os, sys, time

MODULE = sys.argv[1]

class Pause:
    def find_spec(self, name, path=None, target=None):
        if name == MODULE:
            sys.meta_path.remove(self)
            os.write(1, b"importing " + name.encode() + b"\\n")
            # the signal comes meanwhile; short sleeps, as an import runs code all along: a signal that the
            # kernel hands to another thread (numpy's BLAS threads) is then run by this one within 0.1 s
            for _ in range(int({HANG!r} * 10)):
                time.sleep(0.1)
        return None

sys.meta_path.insert(0, Pause())
sys.argv[1:] = ["list"]
from infomarket_entry import main
sys.exit(main())
"""


def test_the_console_script_is_the_light_entry():
    import tomllib

    scripts = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts == {"infomarket": "infomarket_entry:main"}


@pytest.mark.parametrize(("module", "sig"), [
    ("numpy", signal.SIGINT),  # among the first of the package's imports
    ("numba", signal.SIGINT),
    ("infomarket.engine", signal.SIGTERM),
    ("infomarket.cli", signal.SIGINT),  # the last module of the entry's import
    ("infomarket.runner.cli", signal.SIGINT),  # imported by the parser, before the command's handling
])
def test_a_stop_during_the_start_up_imports_ends_the_command_with_one_line(procs, module, sig):
    proc = procs.start([sys.executable, "-c", _START_SCRIPT, module], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline() == f"importing {module}\n", proc.communicate()
    os.killpg(proc.pid, sig)  # a terminal's Ctrl-C reaches the whole process group
    out, err = proc.communicate(timeout=HANG)
    assert (proc.returncode, err, out) == (128 + sig, "infomarket: error: interrupted\n", "")


_STRAY_SCRIPT = f"""
import os, subprocess, sys, time
from infomarket import interrupts

with interrupts.handling():
    started = subprocess.Popen([sys.executable, "-c", "import time; time.sleep({HANG!r})"], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)  # a program the command started: not its to end
    pid = os.fork()
    if pid == 0:  # a fork that nothing registered (a pool worker whose start a stop cut short)
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        time.sleep({HANG!r})
        os._exit(0)
    print(pid, started.pid, flush=True)
    interrupts.exit_now(130)
"""


def test_a_stopped_command_leaves_no_fork_of_itself_behind(procs):
    proc = procs.start([sys.executable, "-c", _STRAY_SCRIPT], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    out, err = proc.communicate(timeout=HANG)
    assert proc.returncode == 130 and err == "", err
    fork, started = map(int, out.split())
    assert session_members(proc.pid) == [started]  # the fork is gone (reaped), the started program is not
