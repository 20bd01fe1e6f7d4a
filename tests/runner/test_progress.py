"""Progress of a resumed sweep: the runs found done count towards the total, not towards the rate, so the
time left is that of the runs still to make (hand numbers: 10 runs made in 1 s, 90 left -> 9 s)."""
import io

from rich.console import Console
from rich.progress import Progress

from infomarket.runner import progress as prog


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_plain_lines_rate_counts_only_the_runs_made(monkeypatch):
    clock = Clock()
    monkeypatch.setattr(prog.time, "monotonic", clock)
    out = io.StringIO()
    lines = prog._Lines("sweep", 1000, out, every=0.5)
    lines.skip(900)
    clock.t += 1.0
    lines.advance(10)
    assert out.getvalue().strip() == "sweep: 910/1000 runs, 10.0 runs/s, ~9 s left"


def test_the_bar_forgets_the_runs_found_done(monkeypatch):
    clock = Clock()
    monkeypatch.setattr(prog.time, "monotonic", clock)
    with Progress(console=Console(file=io.StringIO()), get_time=clock) as p:
        bar = prog._Bar(p, p.add_task("sweep", total=1000, rate=""))
        bar.skip(900)
        clock.t += 1.0
        bar.advance(5)
        clock.t += 1.0
        bar.advance(5)
        task = p.tasks[0]
        assert task.completed == 910
        assert task.speed == 5.0  # rich's estimate: 5 runs per second between the two samples
        assert task.time_remaining == 18.0
        assert task.fields["rate"] == "5.0 runs/s"  # the rate printed beside the bar
