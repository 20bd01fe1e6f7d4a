"""Progress for long work: a live bar on a terminal, plain periodic lines otherwise (CI, logs)."""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn


class _Lines:
    """Non-terminal progress: one line at most every ``every`` seconds, and one at the end."""

    def __init__(self, label: str, total: int, stream, every: float = 10.0):
        self.label, self.total, self.stream, self.every = label, total, stream, every
        self.done = self.skipped = 0
        self.t0 = self.last = time.monotonic()

    def skip(self, k: int) -> None:
        """Count ``k`` runs done before this process (a resumed sweep) without counting them in the rate;
        the runs start now, so what came before (compiling the kernel, checking the store) is not in the
        rate either (a reproduce's first estimate was 681 s for a 27 s job)."""
        self.done += k
        self.skipped += k
        self.t0 = time.monotonic()

    def advance(self, k: int = 1) -> None:
        self.done += k
        now = time.monotonic()
        if now - self.last >= self.every or self.done == self.total:
            rate = (self.done - self.skipped) / max(now - self.t0, 1e-9)
            left = (self.total - self.done) / rate if rate > 0 else float("inf")
            print(f"{self.label}: {self.done}/{self.total} runs, {rate:.1f} runs/s, ~{left:.0f} s left",
                  file=self.stream, flush=True)
            self.last = now


class _Bar:
    def __init__(self, progress: Progress, task):
        self.progress, self.task = progress, task
        self.t0 = time.monotonic()
        self.done = 0

    def skip(self, k: int) -> None:
        # a reset forgets rich's speed samples and restarts its clock, so neither the runs already done
        # nor the time spent before the runs start (compiling, checking the store) inflate the time left
        task = next(t for t in self.progress.tasks if t.id == self.task)
        self.progress.reset(self.task, total=task.total, completed=int(task.completed) + k, rate="")
        self.t0 = time.monotonic()

    def advance(self, k: int = 1) -> None:
        self.done += k
        rate = self.done / max(time.monotonic() - self.t0, 1e-9)
        self.progress.update(self.task, advance=k, rate=f"{rate:.1f} runs/s")


class _Silent:
    def skip(self, k: int) -> None:
        pass

    def advance(self, k: int = 1) -> None:
        pass


@contextmanager
def progress(label: str, total: int, *, enabled: bool = True, stream=None):
    """Context manager yielding an object with ``advance(k)`` (runs made) and ``skip(k)`` (runs found done,
    called once when the runs start: the rate is measured from then); prints nothing when not ``enabled``."""
    stream = stream or sys.stderr
    if not enabled:
        yield _Silent()
        return
    if stream.isatty():
        columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                   TextColumn("{task.fields[rate]}"), TimeRemainingColumn())
        with Progress(*columns, console=Console(file=stream), transient=False) as bar:
            yield _Bar(bar, bar.add_task(label, total=total, rate=""))
    else:
        yield _Lines(label, total, stream)
