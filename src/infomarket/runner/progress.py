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


def busy_markdown(busy: dict | None) -> str:
    """The Cost section's lines on how busy the study kept the machine (empty without a record)."""
    if not busy:
        return ""
    return (f"Machine: {busy['wall_seconds']:.0f} s of wall time on {busy['workers']} worker(s); "
            f"{busy['runs']} runs made now, {busy['run_seconds']:.0f} s in runs (summed over workers), "
            f"{busy['compile_seconds']:.1f} s compiling or loading kernels; "
            f"**{100 * busy['share_in_runs']:.0f} % of the workers' wall time in runs**"
            + (f"; the main process {busy['plan_seconds']:.0f} s checking the store and planning sweeps, "
               f"{busy['write_seconds']:.0f} s writing parts, {busy['search_seconds']:.0f} s in the searches' own "
               f"work (optimisers, reading values)" if busy.get("search_seconds") else "") + ".\n")
