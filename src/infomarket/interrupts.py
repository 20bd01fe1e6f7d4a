"""Ctrl-C and SIGTERM stop every infomarket command at once, whatever it is doing, without a race.

Python turns SIGINT into ``KeyboardInterrupt``, but only when the main thread runs Python bytecode, and an
exception raised there is not always delivered.  A command spends its time in three places where that
fails, and each has its own remedy here, none of which waits for or guesses at a moment:

* **Compiling** (numba and LLVM, up to a minute for a step kernel on a busy machine) runs in C: no Python
  handler can run until it ends.  ``compiled_apart`` compiles in a forked child and waits for it; the wait
  is a system call that a signal interrupts, so the parent kills the child's process group at once and
  stops.  A child that finished has written numba's disk cache, from which the parent then loads.
* **LLVM's callbacks into Python** (llvmlite's object cache, through ctypes): an exception raised inside
  one is printed as "Exception ignored" and dropped, and the compile goes on.  The handler never raises
  while llvmlite is on the stack: it sets a profile function (``sys.setprofile``) that raises at the
  first call or return made with no llvmlite frame left, i.e. as soon as Python is out of llvmlite.
  Nothing is timed and nothing is sent again.
* **Pool workers and children**: ``detach`` puts each in its own process group with the default
  dispositions (a signal ends it at once, even inside a kernel), and makes it die with its parent
  (Linux ``PR_SET_PDEATHSIG``); the parent ends them with SIGKILL to their group (``kill_group``).
  The stop signals are blocked across each fork, so one cannot land in a child before it is detached,
  and let through again only once the fork has returned to its caller: at-fork hooks drop exceptions.

A stretch that an exception must not land in (DuckDB's import aborts when one does) runs in ``held()``,
whose end raises a stop that came meanwhile.  The request to stop is sticky: ``check`` raises again at the safe
points (after each kernel call, after
each finished task), so a ``KeyboardInterrupt`` lost anyway (raised inside a finalizer, say) cannot let a
command run on.  SIGTERM takes the same path as Ctrl-C (finished work kept, the resume command printed)
and exits with 143 instead of 130.

``handling()`` is active for the duration of one command line (``cli.main``); elsewhere (the Python API,
tests) nothing here changes Python's own behaviour.
"""
from __future__ import annotations

import contextlib
import ctypes
import os
import pickle
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

try:
    import fcntl
except ImportError:  # pragma: no cover - not on Windows: compiles are then not coordinated
    fcntl = None

T = TypeVar("T")
SIGNALS = (signal.SIGINT, signal.SIGTERM)
_LLVMLITE = os.sep + "llvmlite" + os.sep
_PR_SET_PDEATHSIG = 1


class _State:
    active = False  # handling() is in force in this process
    signum = 0  # the first stop signal received while active (sticky)
    profile = None  # the profile function ``_deliver`` stands in for
    held = False  # the stop signals are blocked for a fork (``_before_fork``)
    deferred = False  # inside ``held()``: a stop is noted, raised at its end


class Stop:
    """What ``handling()`` yields: ``signum``, the stop signal received in the block (0: none), kept after it."""

    signum = 0


_state = _State()


# ------------------------------------------------------------------------------------------ handler
def _in_llvmlite(frame) -> bool:
    while frame is not None:
        if _LLVMLITE in frame.f_code.co_filename:
            return True
        frame = frame.f_back
    return False


def _handler(signum, frame) -> None:
    _state.signum = _state.signum or signum
    if _state.deferred:  # inside ``held``: raised when it ends
        return
    if _in_llvmlite(frame):  # raised here it would be dropped: raise it at the first event outside llvmlite
        if sys.getprofile() is not _deliver:
            _state.profile = sys.getprofile()
            sys.setprofile(_deliver)
        return
    raise KeyboardInterrupt


def _deliver(frame, event, arg) -> None:
    """A profile function, set only after a stop landed in llvmlite: at the first call or return with no
    llvmlite frame on the stack it puts the previous profile function back and raises there."""
    if _in_llvmlite(frame):
        return
    sys.setprofile(_state.profile)
    raise KeyboardInterrupt


@contextlib.contextmanager
def handling():
    """SIGINT and SIGTERM stop the command (``KeyboardInterrupt``) while the block runs, even where the
    parent left SIGINT ignored or blocked (a script's background job): a command that cannot be stopped
    is worse.  The previous handlers are put back after it.  Main thread only; elsewhere it does nothing."""
    stop = Stop()
    if threading.current_thread() is not threading.main_thread() or _state.active:
        yield stop
        return
    before = {s: signal.getsignal(s) for s in SIGNALS}
    _state.active, _state.signum = True, 0
    for s in SIGNALS:
        signal.signal(s, _handler)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, set(SIGNALS))
    try:
        yield stop
    finally:
        for s, h in before.items():
            signal.signal(s, h if h is not None else signal.SIG_DFL)
        if sys.getprofile() is _deliver:
            sys.setprofile(_state.profile)
        stop.signum = _state.signum
        _state.active, _state.signum = False, 0


@contextlib.contextmanager
def held():
    """A stop held back for the block: for a stretch that an exception must not land in, e.g. a C
    extension's import that aborts the program when one does; a stop meanwhile is raised when the block
    ends, so it is delayed, never lost.  Main thread, inside ``handling`` only."""
    if not _state.active or _state.deferred or threading.current_thread() is not threading.main_thread():
        yield
        return
    _state.deferred = True  # the handler notes the stop and returns (another thread may take the signal)
    try:
        yield
    finally:
        _state.deferred = False
    check()


def requested() -> int:
    """The stop signal received (0: none) while ``handling()`` is in force."""
    return _state.signum


def check() -> None:
    """A safe point: raise ``KeyboardInterrupt`` if a stop was asked for (again, if one was lost)."""
    if _state.signum:
        raise KeyboardInterrupt


def raise_stopped(exc: BaseException):
    """Raise ``exc`` as the stop it is: a ``KeyboardInterrupt`` when a stop signal came (a signal that lands
    inside threading's own bookkeeping can surface as another error, e.g. "release unlocked lock")."""
    if _state.signum and not isinstance(exc, KeyboardInterrupt):
        raise KeyboardInterrupt from exc
    raise exc


def exit_code() -> int:
    """The exit status of a stopped command: 128 + the signal (130 for Ctrl-C, 143 for SIGTERM)."""
    return 128 + (_state.signum or signal.SIGINT)


def exit_now(code: int) -> None:
    """End the program now, after a stop: what it keeps is committed, its children are ended and its
    files closed, so the interpreter's own teardown (finalizers of numba's and LLVM's objects, seconds
    on a loaded machine) would only delay the exit.  Any fork of the program still alive (a pool worker
    whose start a stop cut short, so the pool never knew it) is killed and reaped first, so none outlives
    it even for the moment its death signal takes.  Only for the program itself, never a library call."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    for pid in forks():
        kill_group(pid)
        with contextlib.suppress(ChildProcessError):
            os.waitpid(pid, 0)
    os._exit(code)


def forks() -> list[int]:
    """This process's children that are forks of it, not programs it started: the same executable and
    command line (Linux ``/proc``; elsewhere none)."""
    me = os.getpid()
    try:
        mine = Path("/proc/self/cmdline").read_bytes(), os.readlink("/proc/self/exe")
    except OSError:
        return []
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            if int(stat[stat.rindex(")") + 2:].split()[1]) != me:  # state ppid ...
                continue
            if ((entry / "cmdline").read_bytes(), os.readlink(entry / "exe")) == mine:
                found.append(int(entry.name))
        except (OSError, ValueError):  # gone meanwhile, or not readable
            continue
    return found


def _before_fork() -> None:
    """Signals held while a command forks: between the fork and the child's own setup a signal to the
    command's process group reaches the child too, where the command's handler would raise inside the
    fork's bookkeeping (printed as "Exception ignored")."""
    if _state.active:
        _state.held = True
        signal.pthread_sigmask(signal.SIG_BLOCK, set(SIGNALS))


def _after_fork_in_parent() -> None:
    """The signals held for the fork stay blocked until the fork's caller runs again: let through here, a
    pending stop's ``KeyboardInterrupt`` would be raised inside this at-fork hook (or a later one), where
    Python drops it ("Exception ignored in ...") and the command runs on.  A profile function lets them
    through at the first call or return made outside the at-fork hooks (``_release_after``)."""
    if not _state.held:
        return
    _state.held = False
    try:
        caller = sys._getframe(1)  # the frame that called os.fork: the hooks run inside that call
    except ValueError:  # no Python caller: nowhere better to raise a stop
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(SIGNALS))
        return
    sys.setprofile(_release_after(caller, sys.getprofile()))


def _release_after(caller, previous):
    """A profile function that unblocks the stop signals at the first event of this thread outside the
    at-fork hooks running in ``caller``'s fork call, i.e. once the fork has returned to ``caller``; the
    profile function ``previous`` is put back first.  A pending stop's handler raises there, in
    ``caller`` (or wherever the thread has gone), as a signal arriving just after the fork would."""
    at = caller.f_lasti  # the call of os.fork: unchanged while the hooks run, past it once fork returned

    def release(frame, event, arg) -> None:
        if frame is not caller and caller.f_lasti == at:
            f = frame.f_back
            while f is not None and f is not caller:
                f = f.f_back
            if f is caller:  # a frame of an at-fork hook, called from inside the fork
                return
        sys.setprofile(previous)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(SIGNALS))

    return release


def _after_fork_in_child() -> None:
    """In every forked child of a command: the default dispositions (a signal ends it at once, quietly),
    no stop inherited; then the signals held for the fork are let through."""
    if _state.active:
        for s in SIGNALS:
            signal.signal(s, signal.SIG_DFL)
        _state.active, _state.signum = False, 0
    if _state.held:
        _state.held = False
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(SIGNALS))


if hasattr(os, "register_at_fork"):
    os.register_at_fork(before=_before_fork, after_in_parent=_after_fork_in_parent,
                        after_in_child=_after_fork_in_child)


# ----------------------------------------------------------------------------------------- children
def detach(parent: int | None = None) -> None:
    """In a freshly forked child (a pool worker, a compile): its own process group, so a terminal's Ctrl-C
    reaches only the command, which then ends the group; the default signal dispositions; and death with
    ``parent`` (Linux), so that no child outlives a command killed outright."""
    for s in SIGNALS:
        signal.signal(s, signal.SIG_DFL)
    with contextlib.suppress(OSError):
        os.setpgid(0, 0)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if parent is not None and os.getppid() != parent:  # the parent died before the line above
        os._exit(1)


def kill_group(pid: int) -> None:
    """SIGKILL the process ``pid`` and its process group (one that ``detach`` made): cannot be caught,
    so it ends the child even inside compiled code."""
    for kill in (os.killpg, os.kill):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            kill(pid, signal.SIGKILL)


def compiled_apart(compile_: Callable[[], T], marker: Path | None) -> T:
    """``compile_()``, whose first call in a process compiles and caches on disk, made stoppable: while a
    command is running (``handling``) and ``marker`` does not exist yet, it is first run in a forked
    child (which creates ``marker`` when it succeeds), so a signal during the compile kills the child at
    once; then it runs here, loading from the cache.  A child that failed hands its error back, raised
    here (a failed compile is not cached: running it here would compile it all again); an error it
    cannot hand back is left to the call here.  ``marker`` None (not cacheable), outside a command, off
    the main thread or without ``fork``: just ``compile_()``."""
    with one_compiler(marker):
        if _TOGETHER.child:  # in compiled_together's child: compile here, and say it is in the cache
            out = _here(compile_)
            if marker is not None:
                marker.touch()
            return out
        if (marker is None or not _state.active or marker.exists() or not hasattr(os, "fork")
                or threading.current_thread() is not threading.main_thread()):
            return _here(compile_)
        return _in_child(compile_, marker)


class _Together:
    child = False  # this process is compiled_together's child


_TOGETHER = _Together()


def compiled_together(work: Callable[[], object], markers) -> None:
    """Run ``work`` (calls that reach ``compiled_apart``, e.g. building each of a command's kernels) first in
    one forked child, in which each of them compiles in place and leaves its marker; the calls made here
    afterwards then load from the cache.  One child for all: the step's helpers are typed once per process
    (docs/testing.md), and a child per kernel typed them again for every kernel.  Nothing happens outside a
    command (``handling``), off the main thread, without ``fork``, or when every one of ``markers`` (the
    kernels' ``generated.compile_marker``) exists; what failed in the child is met again by the calls here,
    each in a child of its own as before.  A stop signal kills the child at once and is raised here."""
    if (not _state.active or not hasattr(os, "fork") or threading.current_thread() is not threading.main_thread()
            or all(m is None or m.exists() for m in markers)):
        return

    def child() -> None:
        _TOGETHER.child = True
        work()

    _forked(child)
    check()


def _forked(work: Callable[[], object]) -> None:
    """Run ``work`` in a forked child (``detach``ed; it exits 0, or 1 on any exception) and wait for it,
    polling: a stop signal raises here within 50 ms whichever thread of this process it landed on (a
    blocking ``waitpid`` missed one that another thread, a progress bar's or a notice's timer, took while
    this one held the signals for the fork).  On any exception the child is killed with its group and
    reaped before it propagates; a stop is held back from the fork until then (``held``): let through
    between the fork and the wait, it left the child running, its pid lost."""
    parent, pid = os.getpid(), 0
    try:
        with held():
            pid = os.fork()
            if pid == 0:  # pragma: no cover - the child (its coverage is not collected)
                code = 1
                try:
                    detach(parent)
                    work()
                    code = 0
                except BaseException:  # noqa: BLE001 - the parent meets it again
                    pass
                finally:
                    os._exit(code)
        while os.waitpid(pid, os.WNOHANG) == (0, 0):
            time.sleep(0.05)
    except BaseException:
        if pid:
            kill_group(pid)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)
        raise


_COMPILING = threading.local()


@contextlib.contextmanager
def one_compiler(marker: Path | None):
    """Hold the lock of ``marker``'s generated module while the block compiles it: two processes that meet
    one kernel at once (test workers, two commands) would both compile it; the second waits and loads what
    the first cached.  Not nested (a process holding one lock takes no other, so none waits in a circle);
    the wait polls, so a stop signal ends it (``check``).  Without ``fcntl`` or a marker: no lock."""
    if marker is None or fcntl is None or getattr(_COMPILING, "held", False):
        yield
        return
    path = marker.with_name(marker.name.split(".", 1)[0] + ".lock")
    with open(path, "a") as fh:
        while True:
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                check()
                time.sleep(0.05)
        _COMPILING.held = True
        try:
            yield
        finally:
            _COMPILING.held = False
            fcntl.flock(fh, fcntl.LOCK_UN)


def _in_child(compile_: Callable[[], T], marker: Path) -> T:
    with tempfile.TemporaryFile() as failure:
        def work() -> None:
            try:
                compile_()
                marker.touch()
            except Exception as exc:  # handed to the parent, which raises it
                with contextlib.suppress(Exception):
                    failure.write(pickle.dumps(exc))
                    failure.flush()
                raise

        _forked(work)
        failure.seek(0)
        error = _unpickled(failure.read())
    if error is not None:
        check()
        raise error
    return _here(compile_)


def _unpickled(data: bytes) -> Exception | None:
    """The exception a child pickled, or None (nothing written, or it does not load here)."""
    if not data:
        return None
    try:
        error = pickle.loads(data)
    except Exception:  # noqa: BLE001 - the parent then compiles and meets the error itself
        return None
    return error if isinstance(error, Exception) else None


def _here(compile_: Callable[[], T]) -> T:
    check()
    out = compile_()
    check()  # a stop that came in an LLVM callback near the end is raised here at the latest
    return out


def wait_for(call: Callable[[], T], cancel: Callable[[], object]) -> T:
    """``call()`` (a blocking call into a library that does not look at signals, e.g. a DuckDB query) run
    in a thread while this thread waits: a signal stops the wait at once, ``cancel()`` asks the library
    to stop, and ``KeyboardInterrupt`` propagates without waiting for it (a cancel that came before the
    library's call began may be ignored: the thread then ends with the call, or with the program)."""
    check()  # a stop swallowed before the call (the call itself would never see it)
    box: dict[str, object] = {}

    def work() -> None:
        try:
            box["value"] = call()
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
            box["error"] = exc

    try:
        thread = threading.Thread(target=work, daemon=True, name="infomarket-wait")
        thread.start()
        thread.join()  # a plain lock wait, which a signal interrupts cleanly
    except BaseException as exc:  # noqa: BLE001 - the wait is cancelled, then raised again as a stop
        with contextlib.suppress(Exception):
            cancel()
        raise_stopped(exc)
    if "error" in box:
        raise box["error"]
    return box["value"]
