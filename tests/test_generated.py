"""Generated-module helpers (``infomarket.generated``): a Ctrl-C while numba compiles is not lost."""
import os
import subprocess
import sys
from pathlib import Path

import infomarket as im

# LLVM calls back into Python through ctypes when it has compiled an object; a Ctrl-C that lands in that
# callback is printed as "Exception ignored" and lost (found when `infomarket run` went on for minutes
# after Ctrl-C on a loaded machine).  The script sends SIGINT to itself from inside the real callback.
SCRIPT = r'''
import os, signal, sys, time
import numba
from numba.core.registry import cpu_target
from infomarket.generated import ctrl_c_survives_compiling

engine = cpu_target.target_context.codegen()._engine
engine = getattr(engine, "_ee", engine)  # llvmlite's ExecutionEngine behind numba's proxy
original = engine._object_cache_notify
calls = []

def ctrl_c_inside(ll_module, buf):
    calls.append(1)
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(0.05)
    return original(ll_module, buf)

engine._object_cache_notify = ctrl_c_inside
try:
    if sys.argv[1] == "guarded":
        with ctrl_c_survives_compiling():
            numba.njit(lambda x: x + 1)(1)
    else:
        numba.njit(lambda x: x + 1)(1)
    time.sleep(0.3)
    print("finished", len(calls))
except KeyboardInterrupt:
    print("interrupted", len(calls))
'''


def _run(mode: str) -> list[str]:
    env = {**os.environ, "PYTHONPATH": str(Path(im.__file__).parents[1])}
    out = subprocess.run([sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True, env=env,
                         timeout=120)
    return out.stdout.split()


def test_a_ctrl_c_inside_an_llvm_callback_is_lost_without_the_guard():
    """The hazard is real (if numba stops calling back, this says so, and the guard may go)."""
    what, calls = _run("plain")
    assert int(calls) >= 1 and what == "finished"


def test_a_ctrl_c_inside_an_llvm_callback_interrupts_the_compile_with_the_guard():
    what, calls = _run("guarded")
    assert int(calls) >= 1 and what == "interrupted"


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
