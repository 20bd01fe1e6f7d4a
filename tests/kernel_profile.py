"""Where a test run's CPU time goes: a pytest plugin that writes, per test, its CPU seconds and every numba
compile it triggered (a cache miss: the function, its module, its CPU seconds), one JSON object a line.

    INFOMARKET_CACHE_DIR=$(mktemp -d) NUMBA_CACHE_DIR=$(mktemp -d) KERNEL_PROFILE=prof.jsonl \\
        .venv/bin/python -m pytest -q -n 0 -p tests.kernel_profile
    .venv/bin/python -m tests.kernel_profile prof.jsonl      # the summary: kernels, their tests, top files

CPU seconds (``time.process_time``), not wall time, so a busy machine does not change them; with fresh
cache folders every kernel is compiled once, by the first test that needs it (docs/testing.md).
"""
from __future__ import annotations

import collections
import json
import os
import sys
import time

import pytest
from numba.core import event

_STATE = {"test": "<collection>", "depth": 0, "start": 0.0}
_OUT: list = []


def _emit(record: dict) -> None:
    record["worker"] = os.environ.get("PYTEST_XDIST_WORKER", "main")  # which xdist worker (or none) ran it
    if not _OUT:
        _OUT.append(open(os.environ.get("KERNEL_PROFILE", "kernel-profile.jsonl"), "a"))
    _OUT[0].write(json.dumps(record) + "\n")
    _OUT[0].flush()


class _Compiles(event.Listener):
    """numba fires ``numba:compile`` only when it compiles (not when it loads from its cache); nested
    compiles (a kernel's callees) are counted inside the outermost one."""

    def on_start(self, ev):
        if _STATE["depth"] == 0:
            _STATE["start"] = time.process_time()
        _STATE["depth"] += 1

    def on_end(self, ev):
        _STATE["depth"] -= 1
        if _STATE["depth"] == 0:
            func = ev.data["dispatcher"].py_func
            _emit({"compile": func.__qualname__, "module": func.__module__, "test": _STATE["test"],
                   "cpu": time.process_time() - _STATE["start"]})


_USES: dict = {}


def _record_uses(module) -> None:
    """Note every generated module (step kernel, state view) a test loads, compiled or loaded
    from a cache: its callers look ``load_generated`` up as a global, so it is wrapped in each."""
    inner = module.load_generated

    def load_generated(prefix, key, *args, **kwargs):
        _USES.setdefault(_STATE["test"], set()).add(f"infomarket_{prefix}_{key}")
        return inner(prefix, key, *args, **kwargs)

    module.load_generated = load_generated


def pytest_configure(config):
    from infomarket import generated  # the package only once pytest runs with this plugin
    from infomarket.engine import specialise

    event.register("numba:compile", _Compiles())
    for module in (generated, specialise):
        _record_uses(module)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    _STATE["test"] = item.nodeid
    start, children = time.process_time(), os.times()
    yield
    after = os.times()
    _emit({"test": item.nodeid, "cpu": time.process_time() - start,
           "children_cpu": after.children_user + after.children_system
           - children.children_user - children.children_system,
           "uses": sorted(_USES.pop(item.nodeid, ()))})
    _STATE["test"] = "<between tests>"


def summary(path: str, top: int = 40) -> str:
    tests, compiles = {}, []
    for line in open(path):
        record = json.loads(line)
        if "compile" in record:
            compiles.append(record)
        else:
            tests[record["test"]] = record
    users = collections.defaultdict(set)  # generated module -> the tests that loaded it
    for name, t in tests.items():
        for module in t.get("uses", ()):
            users[module].add(name)
    kernels = collections.defaultdict(list)  # step kernel -> its compiles (step_all, or a dispatch alone)
    for c in compiles:
        if (c["module"] or "").startswith("infomarket_kernel"):  # None: a function made at run time
            kernels[c["module"]].append(c)
    files, workers, worker_compiles = collections.Counter(), collections.Counter(), collections.Counter()
    for name, t in tests.items():
        files[name.split("::")[0]] += t["cpu"] + t["children_cpu"]
        workers[t.get("worker", "?")] += t["cpu"] + t["children_cpu"]
    for c in compiles:
        worker_compiles[c.get("worker", "?")] += c["cpu"]
    kernel_cpu = sum(c["cpu"] for cs in kernels.values() for c in cs)
    lines = [f"{len(tests)} tests, {sum(t['cpu'] for t in tests.values()):.0f} CPU s in the test process, "
             f"{sum(t['children_cpu'] for t in tests.values()):.0f} in processes they started",
             f"{len(compiles)} compiles, {sum(c['cpu'] for c in compiles):.0f} CPU s; {len(kernels)} step kernels, "
             f"{kernel_cpu:.0f} CPU s",
             "per worker (CPU s, its processes included; of which compiling): "
             + ", ".join(f"{w} {cpu:.0f} ({worker_compiles[w]:.0f})" for w, cpu in sorted(workers.items())), "",
             "step kernels (CPU s compiling it, tests that loaded it where recorded, the first test that compiled it):"]
    for module, cs in sorted(kernels.items(), key=lambda kv: -sum(c["cpu"] for c in kv[1])):
        used = f"{len(users[module]):4d}" if users else "   ?"
        lines.append(f"{sum(c['cpu'] for c in cs):7.1f} {used}  {module}  {cs[0]['test']}")
    lines += ["", f"the {top} costliest files (CPU s, their processes included):"]
    lines += [f"{cpu:7.1f}  {name}" for name, cpu in files.most_common(top)]
    lines += ["", f"the {top // 2} costliest tests (CPU s, their processes included; the longest bounds a parallel "
                  "run):"]
    costly = sorted(tests.items(), key=lambda kv: -(kv[1]["cpu"] + kv[1]["children_cpu"]))[:top // 2]
    lines += [f"{t['cpu'] + t['children_cpu']:7.1f}  {name}" for name, t in costly]
    return "\n".join(lines)


if __name__ == "__main__":
    print(summary(sys.argv[1]))
