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


def test_time_before_the_runs_start_is_not_in_the_rate(monkeypatch):
    """Issue 21: reproduce's first estimate said ~681 s left for a 27 s job: the seconds spent compiling
    and checking the store before the first run counted as time spent making runs.  Hand numbers: 60 s of
    compiling, then 10 runs in 2 s with 90 left -> 5 runs/s, 18 s left (not 10 / 62 runs/s, 558 s)."""
    clock = Clock()
    monkeypatch.setattr(prog.time, "monotonic", clock)
    out = io.StringIO()
    lines = prog._Lines("paper", 100, out, every=0.5)
    clock.t += 60.0  # compiling kernels, checking the store
    lines.skip(0)  # the runs start (sweep's on_plan)
    clock.t += 2.0
    lines.advance(10)
    assert out.getvalue().strip() == "paper: 10/100 runs, 5.0 runs/s, ~18 s left"
    with Progress(console=Console(file=io.StringIO()), get_time=clock) as p:
        bar = prog._Bar(p, p.add_task("paper", total=100, rate=""))
        clock.t += 60.0
        bar.skip(0)
        clock.t += 2.0
        bar.advance(10)
        assert p.tasks[0].fields["rate"] == "5.0 runs/s"


def test_the_sweep_says_when_its_runs_start_even_with_nothing_found_done(tmp_path, monkeypatch):
    from infomarket.cli import main

    calls = []

    class Recorder(prog._Silent):
        def skip(self, k):
            calls.append(("skip", k))

        def advance(self, k=1):
            calls.append(("advance", k))

    from contextlib import contextmanager

    @contextmanager
    def fake(label, total, *, enabled=True, stream=None):
        yield Recorder()

    monkeypatch.setattr(prog, "progress", fake)
    (tmp_path / "e.toml").write_text('name = "e"\nsteps = 20\nruns = 2\n[swarm]\nrobots = 2\n'
                                     '[[swarm.groups]]\nbehaviour = "naive"\ncount = 2\n')
    assert main(["sweep", str(tmp_path / "e.toml"), "--out", str(tmp_path / "s"), "--workers", "1"]) == 0
    assert calls[0] == ("skip", 0) and sum(k for what, k in calls if what == "advance") == 2
