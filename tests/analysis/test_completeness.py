"""Issue 21 item 4: incomplete or underpowered results say so wherever an answer is printed."""
from __future__ import annotations

import pandas as pd

from infomarket.analysis import completeness, future, headline
from infomarket.analysis.frames import Frames
from infomarket.cli import main
from infomarket.store import Store

from .synthetic import paper_like, write_store
from .test_future import hopeless, sweep


def test_figures_after_store_repair_reports_the_missing_condition(tmp_path, capsys):
    """A damaged part set aside by `store repair` takes a condition of Fig. 7 with it; `figures`,
    without re-running, must say so (it drew Fig. 7 silently before) and not judge Fig. 7's rows."""
    store = write_store(tmp_path / "s", paper_like())
    part = store.part_path("robots", "fig7-3-staking-40")
    part.write_bytes(b"not parquet")  # damaged
    assert main(["store", "repair", str(store.root)]) == 0
    capsys.readouterr()
    out = tmp_path / "f"
    assert main(["figures", str(store.root), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert ("WARNING: fig7: INCOMPLETE: 1 of its 40 conditions have no runs in the store "
            "(byzantines=3,market=staking,rotation_angle=40.0)") in printed
    assert "fig7: wrote fig7.png, fig7.svg (INCOMPLETE design)" in printed
    md = (out / "report.md").read_text()
    assert "## Incomplete designs" in md and "resume with `infomarket sweep fig7 --out STORE`" in md
    table = headline.headline_table(Store(store.root))
    fig7 = table[table.figure.str.startswith("7")]
    assert set(fig7.verdict) == {"inconclusive"} and set(fig7.note) == {"incomplete design"}
    assert "| inconclusive (incomplete design) |" in md
    others = table[~table.figure.str.startswith("7")]
    assert "incomplete design" not in set(others.note)


def test_a_complete_store_and_a_store_swept_from_another_file_have_no_gaps():
    tables = paper_like()
    runs = pd.concat([r for _, r, _ in tables.values()], ignore_index=True)
    assert completeness.gaps(runs) == {}
    other = runs.copy()
    other.loc[other.experiment == "fig7", "condition"] = "speed=3"  # not the shipped grid: not judged
    assert completeness.gaps(other) == {}
    short = runs[~((runs.experiment == "fig2A") & (runs.run == 0))]
    assert completeness.gaps(short) == {}  # every condition of fig2A lost one run: even, not incomplete
    uneven = runs[~((runs.experiment == "fig7") & (runs.condition == "byzantines=1,market=staking,rotation_angle=0")
                    & (runs.run == 0))]
    gap = completeness.gaps(uneven)["fig7"]
    assert gap.missing == () and gap.short == ("byzantines=1,market=staking,rotation_angle=0.0: 7",) and gap.most == 8


def test_headline_rows_map_to_their_experiments():
    assert completeness.affected("7B", {"fig7"}) == ["fig7"]
    assert completeness.affected("4A vs 3A", {"fig3A", "fig4B"}) == ["fig3A"]
    assert completeness.affected("3A-C", {"fig3C"}) == ["fig3C"]
    assert completeness.affected("5B", {"fig5"}) == ["fig5"]
    assert completeness.affected("2A", {"fig2B"}) == []


def test_a_reduced_future_sweep_prints_inconclusive_n_too_small():
    """`sweep future --scale 0.02`: 2 runs per condition, the smallest one-sided Mann-Whitney p is 1/6:
    every answer is inconclusive, and the printed answer says why."""
    table = future.question_table(Frames(robots=sweep(hopeless, runs=2)))
    assert set(table.answer) == {"inconclusive"} and set(table.note) == {"n too small"}
    md = "\n".join(future.to_markdown(future.Section([], table, "")))
    assert md.count("inconclusive (n too small)") == len(table)
    # with the declared 32 runs nothing is "n too small"
    assert set(future.question_table(Frames(robots=sweep(hopeless)))["note"]) == {""}


def test_paper_rows_whose_runs_cannot_reach_their_p_say_n_too_small(paper_frames):
    """Figs. 3-4's run-level test needs p < 0.001: with 3 runs the smallest signed-rank p is 1/8."""
    robots, runs = paper_frames.robots, paper_frames.runs
    few = Frames(robots=robots[robots.run < 3], runs=runs[runs.run < 3])
    table = headline.headline_table(few).set_index("id")
    row = table.loc["fig3A_mannwhitney"]
    assert row.verdict == "inconclusive" and row.note == "n too small"
    assert headline.headline_table(paper_frames).set_index("id").loc["fig3A_mannwhitney"].note == ""
