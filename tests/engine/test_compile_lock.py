"""Two processes that meet one uncompiled kernel at once compile it once: the second waits on the kernel's
lock (``interrupts.one_compiler``) and loads what the first cached, as two test workers or two commands on
one machine would."""
import sys

from infomarket import compiled_cache, interrupts

#: A child: waits for the start file (so both meet the kernel at once), builds a simulation of a small
#: experiment, and prints how many times numba compiled its step loop in this process (0: loaded).
CHILD = r"""
import pathlib, sys, time
from numba.core import event

compiled = []


class Compiles(event.Listener):
    def on_start(self, ev):
        pass

    def on_end(self, ev):
        if ev.data["dispatcher"].py_func.__name__ == "step_all":
            compiled.append(1)


event.register("numba:compile", Compiles())
import infomarket as im

go = pathlib.Path(sys.argv[1])
while not go.exists():
    time.sleep(0.01)
im.Simulation(im.Experiment.model_validate({"steps": 100, "swarm": {"robots": 4, "groups": [
    {"behaviour": "naive", "count": 4}]}}), 1)
print(len(compiled))
"""


def test_two_processes_compile_a_new_kernel_once(procs, tmp_path):
    cache = tmp_path / "cache"  # an empty kernel cache: the kernel is new; the step's pieces as cached already
    cache.mkdir()
    (cache / "compiled").symlink_to(compiled_cache.compiled_root().parent, target_is_directory=True)
    env = {"INFOMARKET_CACHE_DIR": str(cache)}
    go = tmp_path / "go"
    children = [procs.start([sys.executable, "-c", CHILD, go], env=env, stdout=-1, stderr=-1, text=True)
                for _ in range(2)]
    go.touch()
    outs = [c.communicate(timeout=1800) for c in children]
    assert [c.returncode for c in children] == [0, 0], [err[-2000:] for _, err in outs]
    assert sorted(int(out.split()[-1]) for out, _ in outs) == [0, 1]


def test_the_lock_is_not_taken_without_a_marker_nor_twice(tmp_path):
    marker = tmp_path / "kernel_x.simulation.compiled"
    with interrupts.one_compiler(marker):
        assert (tmp_path / "kernel_x.lock").exists()
        with interrupts.one_compiler(tmp_path / "kernel_y.simulation.compiled"):  # nested: no second lock
            pass
        assert not (tmp_path / "kernel_y.lock").exists()
    with interrupts.one_compiler(None):
        pass
