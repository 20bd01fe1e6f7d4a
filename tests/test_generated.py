"""Generated-module helpers (``infomarket.generated``), and a Ctrl-C while numba compiles is not lost."""
import signal
import sys
from pathlib import Path

import pytest

# LLVM calls back into Python through ctypes when it has compiled an object; a KeyboardInterrupt raised in
# that callback is printed as "Exception ignored" and lost (found when `infomarket run` went on for
# minutes after Ctrl-C on a loaded machine).  HOOK makes the real callback send a signal to the command's
# process the first time it is called, and then stay in the callback, running Python, for a while (the
# worst case: every chance the handler gets to run falls inside llvmlite).
HOOK = r"""
import os, signal, sys, time
from numba.core.registry import cpu_target

MAIN, SIG = os.getpid(), int(sys.argv[1])
engine = cpu_target.target_context.codegen()._engine
engine = getattr(engine, "_ee", engine)  # llvmlite's ExecutionEngine behind numba's proxy
original = engine._object_cache_notify
calls = []

def signal_inside(ll_module, buf):
    calls.append(1)
    if len(calls) == 1:
        os.kill(MAIN, SIG)
        for _ in range(200):
            time.sleep(0.001)
    return original(ll_module, buf)

engine._object_cache_notify = signal_inside
"""
PLAIN = HOOK + r"""
import numba
try:
    numba.njit(lambda x: x + 1)(1)
    print("finished", len(calls))
except KeyboardInterrupt:
    print("interrupted", len(calls))
"""
# `infomarket run` with a cold kernel cache, from the callback of the first object LLVM compiles; "here":
# the kernel is compiled in this process (as when it cannot be cached), else in the command's child
COMMAND = HOOK + r"""
import infomarket.engine.simulation as simulation
from infomarket.cli import main
if sys.argv[2] == "here":
    simulation.compile_marker = lambda module, tag: None
sys.argv = sys.argv[:1]
sys.exit(main(["run", "fig2B", "--runs", "2", "--steps", "100", "--workers", "1", "--quiet", "--out", "D"]))
"""


def test_a_ctrl_c_inside_an_llvm_callback_is_lost_without_the_handler(procs):
    """The hazard is real (if numba stops calling back, this says so, and the handler's care may go)."""
    done = procs.run([sys.executable, "-c", PLAIN, str(int(signal.SIGINT))])
    what, calls = done.stdout.split()
    assert int(calls) >= 1 and what == "finished", done.stderr


@pytest.mark.parametrize("where,sig,ignored", [("here", signal.SIGINT, False), ("here", signal.SIGINT, True),
                                               ("child", signal.SIGINT, False), ("child", signal.SIGTERM, False)],
                         ids=["here", "here-ctrl-c-ignored-by-the-parent", "child", "child-sigterm"])
def test_a_signal_inside_an_llvm_callback_stops_the_command(procs, tmp_path, where, sig, ignored):
    """Whether the kernel compiles in the command's process or in its child, and even when the command
    inherited SIGINT ignored (a script's background job): it stops, with the one message and 128 + the
    signal, nothing written, nothing left running, and no "Exception ignored"."""
    out = tmp_path / "D"
    script = tmp_path / "command.py"
    script.write_text(COMMAND)
    done = procs.run([sys.executable, script, str(int(sig)), where], env={"INFOMARKET_CACHE_DIR": str(tmp_path / "c")},
                     ignore_ctrl_c=ignored, cwd=tmp_path)
    assert done.returncode == 128 + sig, done.stderr
    assert done.stderr.strip().splitlines() == ["infomarket: error: interrupted"], done.stderr
    assert not out.exists()
    assert not list((tmp_path / "c" / "kernels").glob("*.compiled"))  # the child was stopped before its end


def test_source_edited_under_a_running_process_is_compiled_but_not_cached(tmp_path, monkeypatch):
    """The cache name hashes the source this process imported; if the files change afterwards, what the
    process compiles comes from the old code and must not be stored where the new code would load it."""
    import pytest

    from infomarket import generated

    monkeypatch.setenv("INFOMARKET_CACHE_DIR", str(tmp_path))
    source = "import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n"
    assert not generated.source_changed_since_import()  # nothing edited: cached as before
    m = generated.load_generated("testcache", "unchanged", source)
    assert Path(m.__file__).parent == tmp_path / "kernels" and m.f(1) == 2

    imported = generated.freeze_package_digest()
    monkeypatch.setattr(generated, "_digest_now", lambda: "not " + imported)  # an edit on disk
    assert generated.source_changed_since_import()
    with pytest.warns(RuntimeWarning, match="not cached"):
        m = generated.load_generated("testcache", "edited", source)
    assert Path(m.__file__).parent != tmp_path / "kernels" and m.f(2) == 3
    assert not (tmp_path / "kernels" / "testcache_edited.py").exists()
