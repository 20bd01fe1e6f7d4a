"""examples/tutorial.ipynb runs from top to bottom, as a user would run it: every cell executed by nbclient
in a Jupyter kernel of its own, whose process session the ``procs`` fixture ends, passed or failed.

The notebook runs in a fixed folder per checkout under the cache (not a fresh temporary one): the rule it
writes is compiled into kernels cached by its file's path, so a fixed path lets every later run of the
suite load them instead of compiling three kernels again."""
from __future__ import annotations

import hashlib
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

from infomarket.generated import cache_root

from .procs import HANG, child_env, session_members

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "examples" / "tutorial.ipynb"


def execute(nb: nbformat.NotebookNode, cwd: Path, procs) -> None:
    """Run every cell of ``nb`` in a new kernel started in ``cwd``, with this checkout's infomarket on its
    path; the kernel process is handed to ``procs``, which ends its session whatever happens."""
    client = NotebookClient(nb, timeout=int(HANG), kernel_name="python3", resources={"metadata": {"path": str(cwd)}})
    client.on_notebook_start = lambda **_: procs.started.append(client.km.provisioner.process)
    client.execute(env=child_env({"MPLBACKEND": "agg"}))


def _outputs(nb: nbformat.NotebookNode, kind: str) -> list:
    return [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs if kind in o.get("data", {})]


def test_the_tutorial_runs_from_top_to_bottom(procs):
    work = cache_root() / "tutorial" / hashlib.sha256(str(ROOT).encode()).hexdigest()[:12]
    work.mkdir(parents=True, exist_ok=True)
    nb = nbformat.read(NOTEBOOK, as_version=4)
    execute(nb, work, procs)  # a cell that raises fails here, naming the cell
    assert len(_outputs(nb, "image/png")) == 2  # the Fig. 2 panels and the sweep's box plot
    text = "".join(o.get("text", "") for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs)
    assert "cautious: every check passed" in text


def test_a_broken_cell_fails_the_run_and_the_kernel_ends(procs, tmp_path):
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(src) for src in
                                         ("x = 1", "raise ValueError('a broken cell')", "print('after')")])
    with pytest.raises(CellExecutionError, match="a broken cell"):
        execute(nb, tmp_path, procs)
    assert nb.cells[2].outputs == []  # nothing after the broken cell ran
    (kernel,) = procs.started
    procs.close()
    assert session_members(kernel.pid) == []
