"""The generated step kernel's name hashes what its machine code depends on, and nothing else."""
import json
import shutil
import sys
from pathlib import Path

import infomarket as im

PACKAGE = Path(im.__file__).resolve().parent

#: In a child: import the package from the folder given (ahead of this checkout's), print where it came
#: from and the kernel names of two shipped experiments.
NAMES = """
import json, sys
sys.path.insert(0, sys.argv[1])
import infomarket as im
from infomarket.engine.specialise import kernel_id
print(json.dumps([im.__file__, kernel_id(im.load_experiment("fig2A")), kernel_id(im.load_experiment("fig4C"))]))
"""


def _checkout(root: Path) -> Path:
    shutil.copytree(PACKAGE, root / "infomarket", ignore=shutil.ignore_patterns("__pycache__"))
    return root


def _names(procs, root: Path) -> list[str]:
    proc = procs.run([sys.executable, "-c", NAMES, str(root)])
    assert proc.returncode == 0, proc.stderr
    where, *names = json.loads(proc.stdout)
    assert Path(where).resolve() == (root / "infomarket" / "__init__.py").resolve()
    return names


def test_two_checkouts_of_the_same_code_share_their_kernels_and_an_edit_does_not(procs, tmp_path):
    # a study run from a second checkout (a worktree) found none of the first one's kernels and compiled
    # every one again, because the generated source named its files by absolute path
    first = _names(procs, _checkout(tmp_path / "one"))
    second = _checkout(tmp_path / "two")
    assert _names(procs, second) == first
    step = second / "infomarket" / "engine" / "step.py"
    step.write_text(step.read_text() + "\n# an edit to compiled code\n")
    edited = _names(procs, second)
    assert edited[0] != first[0] and edited[1] != first[1]
