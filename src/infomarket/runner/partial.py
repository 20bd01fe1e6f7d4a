"""The runs a stop cut short inside a task, kept: a Ctrl-C of a sweep loses only the runs in progress.

A task (up to 64 runs, one store part) is run in groups of ``execute.TOGETHER`` runs; its outputs reach the
parent only when the whole task is done.  A stop used to throw away every finished group of every task in
progress (about 40 runs a task on a long sweep).  ``Keep`` takes each group as it finishes: in memory when
the task runs in this process, else a file per group in a folder of this machine (a local pool's workers
are forks of this process), each written whole and then renamed, so the parent, stopped, reads only whole
groups even while a worker is still writing.  The parent then commits those runs as a part of their own
(``Task.first``): its id names its own runs, so a resumed sweep's parts, made of the runs still missing,
never collide with it, and every run keeps the seed it would have had.
"""
from __future__ import annotations

import os
import pickle
from pathlib import Path

__all__ = ["Keep"]


class Keep:
    """Where a task's finished groups of runs (lists of ``execute.RunOutput``) go (``run_calls``' ``keep``):
    a list here (``folder`` None: the task runs in this process) or one file per group in ``folder`` (a pool
    worker's copy writes, the parent's reads).  The task's last group is not kept: the task's own result
    holds it."""

    def __init__(self, folder: Path | None, total: int):
        self.folder, self.total = folder, total
        self.groups: list[list] = []
        self.seen = 0

    def __call__(self, outputs: list) -> None:
        """Keep ``outputs``, the next group of the task's runs, in order."""
        self.seen += len(outputs)
        if self.seen >= self.total:
            return
        if self.folder is None:
            self.groups.append(outputs)
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.folder / f"{self.seen:06d}.pkl"
        tmp = path.with_suffix(".tmp")
        tmp.write_bytes(pickle.dumps(outputs, protocol=pickle.HIGHEST_PROTOCOL))
        os.replace(tmp, path)

    def kept(self) -> list:
        """The outputs of the groups kept so far, in the task's order."""
        if self.folder is None:
            return [o for g in self.groups for o in g]
        if not self.folder.is_dir():
            return []
        return [o for path in sorted(self.folder.glob("*.pkl")) for o in pickle.loads(path.read_bytes())]
