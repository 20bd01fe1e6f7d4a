"""The attack search's report from synthetic cell searches (the fields a cell's search returns, built
here): paired comparisons on the confirmation seeds with hand-computed estimates, intervals and p-values,
the declared rules' answers, and a figure that draws exactly the numbers the table prints."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import matplotlib
import numpy as np
import pandas as pd
import pytest

from infomarket.errors import ArgumentError
from infomarket.search import report
from infomarket.search.study import load_declarations

matplotlib.use("Agg")
QUESTIONS = load_declarations()["questions"]
N = 8
IDX = np.arange(1, N + 1)


@dataclass(frozen=True)
class Cell:
    defence: str
    byzantines: int

    @property
    def experiment(self) -> str:
        return f"attack_search.{self.defence}.b{self.byzantines}"


@dataclass
class Search:
    """The fields of a cell's search result the report reads (search.driver.CellSearch)."""

    cell: Cell
    confirmation: pd.DataFrame
    chosen: dict
    params: dict
    cost: dict
    done: int = 0
    skipped: int = 0
    candidates: pd.DataFrame = field(default_factory=pd.DataFrame)
    selection: pd.DataFrame = field(default_factory=pd.DataFrame)
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Settings:
    objective: str = "items"
    confirmation_runs: int = N


def study(questions=QUESTIONS, objective="items"):
    return SimpleNamespace(settings=Settings(objective), questions=questions,
                           experiment=SimpleNamespace(swarm=SimpleNamespace(robots=25)))


def frame(values: dict[str, np.ndarray], wealth: dict[str, np.ndarray] | None = None) -> pd.DataFrame:
    rows = [{"attack": a, "run": r, "items": float(v[r]), "liar_wealth": float((wealth or {}).get(a, v * 0)[r])}
            for a, v in values.items() for r in range(len(v))]
    return pd.DataFrame(rows)


def search(defence, byz, *, worst, base, rand, extra=None, wealth=None):
    """A cell whose search's attack is also the worst; reference 10 items on every seed."""
    values = {"cma_best": worst, "base_best": base, "rnd_best": rand, "truthful": np.full(N, 10.0)}
    chosen = {"search": "cma_best", "random": "rnd_best", "baseline": "base_best", "worst": "cma_best",
              "reference": "truthful"}
    cost = {"search": {"runs": 2048, "env_steps": 2048 * 30000, "seconds": 300.0},
            "confirmation": {"runs": 4 * N, "env_steps": 4 * N * 30000, "seconds": 5.0}}
    ext = {"adaptive": frame({"policy1": extra})} if extra is not None else {}
    cands = pd.DataFrame({"searcher": ["cma", "cma", "random", "cma", "random"], "fitness": np.arange(5.0)})
    return Search(Cell(defence, byz), frame(values, wealth), chosen, {"cma_best": {"rot_base": 170.0}}, cost,
                  candidates=cands, extra=ext)


# cell A: per-seed loss 0.01 i (within 10 %); the search beats the best baseline by 1.0 + 0.1 i items on
# seed i; against the random search it differs by +-0.2 (nothing shown, with power); the adaptive searcher
# beats it by 0.5 + 0.05 i
W_A = 10.0 - 0.1 * IDX
A = search("staking", 1, worst=W_A, base=W_A + 1.0 + 0.1 * IDX, rand=W_A - 0.2 * (-1.0) ** IDX,
           extra=W_A - 0.5 - 0.05 * IDX)
# cell B: per-seed loss 0.25 + 0.01 i (beyond 10 %); the search differs from the baseline by +-3 (too noisy
# to decide) and from the random search by -(1.0 + 0.1 i)
W_B = 7.5 - 0.1 * IDX
B = search("staking", 3, worst=W_B, base=W_B - 3.0 * (-1.0) ** IDX, rand=W_B + 1.0 + 0.1 * IDX)


@pytest.fixture(scope="module")
def analysis():
    return report.analyse(study(), [A, B])


def test_the_worst_case_is_the_most_damaging_confirmed_attack_decided_over_all(analysis):
    a, b = analysis["cells"]
    # cell A's confirmed attacks, per-seed loss: search 0.01 i, random 0.01 i + 0.02 (-1)^i, baseline
    # -(0.1 + 0.01 i) + 0.01 i = -0.1, adaptive 0.05 + 0.015 i: the adaptive attacker is the worst (Walsh
    # median 0.05 + 0.015 x 4.5), and it straddles the 10 % margin (0.065 .. 0.17): neither shown within
    # nor beyond, so the cell is inconclusive although the selection's worst (the search's) is within
    assert a["worst"] == {"role": "adaptive", "loss": pytest.approx(0.1175)}
    assert a["worst_case_bounded"]["loss"] == pytest.approx(0.1175) and a["bounded"] == "inconclusive"
    assert set(a["roles"]) == {"search", "random", "baseline", "adaptive"}
    assert a["roles"]["adaptive"]["attack"] == "policy1" and a["roles"]["search"]["attack"] == "cma_best"
    # the search's interval at the decision's levels: "beyond" over the 7 (cell, attack) of the family,
    # Holm rejects B's random (p 0.0023 < 0.05/7) and B's search (1/256 < 0.05/6), stops at 0.05/5 = 0.01:
    # the lower bound at 0.01 is the 2nd smallest Walsh average (P(T+ <= 1) = 2/256 <= 0.01 < 3/256):
    # 0.015; the upper at A's "within" level: its intersection-union p (0.90, the adaptive's) and B's (1)
    # stop Holm at its first step, 0.05 / 2: the 4th largest Walsh average, 0.07
    assert a["roles"]["search"]["interval"] == pytest.approx([0.015, 0.07])
    assert a["worst_case_bounded"]["level_within"] == 0.05 / 2
    # cell B: the search's attack loses 0.25 + 0.01 i on every seed: shown beyond, "no"
    assert b["bounded"] == "no" and b["worst_case_bounded"]["roles"]["search"]["beyond"]
    assert b["worst"]["loss"] == pytest.approx(max(v["loss"] for v in b["roles"].values()))
    assert analysis["bounded_by_defence"]["staking"]["answer"] == "no"
    # the adaptive attacker is confirmed more damaging than the search's attack in A (1/256 each seed, Holm)
    assert a["more_damaging_than_search"] == ["adaptive"] and b["more_damaging_than_search"] == []


def test_search_vs_best_baseline_and_random_search(analysis):
    a, b = analysis["cells"]
    beats = a["search_beats_baseline"]
    # d_i = -(1.0 + 0.1 i): HL -1.45, interval [-1.7, -1.2]; baseline items 11 on every seed: 13.2 % more damage
    assert (beats["hl"], beats["low"], beats["high"]) == pytest.approx((-1.45, -1.7, -1.2))
    assert beats["percent"] == pytest.approx(1.45 / 11.0)
    assert (beats["percent_low"], beats["percent_high"]) == pytest.approx((1.2 / 11.0, 1.7 / 11.0))
    assert beats["answer"] == "yes" and beats["p"] == pytest.approx(1 / 256)
    # +-0.2 against the random search: not shown; simulated at the declared -10 % of its median the
    # differences are -0.955 +- 0.2, all negative, so every simulated test rejects: power 1, a "no"
    rnd = a["search_beats_random"]
    assert rnd["hl"] == pytest.approx(0.0) and not rnd["significant"]
    assert rnd["power"] == 1.0 and rnd["answer"] == "no"
    assert rnd["declared"] == pytest.approx(-0.1 * np.median(W_A + 0.2 * (-1.0) ** IDX))
    # cell B: +-3 noise, the same declared effect cannot be seen often: inconclusive, not "no"
    nb = b["search_beats_baseline"]
    assert nb["power"] < 0.8 and nb["answer"] == "inconclusive"
    assert b["search_beats_random"]["answer"] == "yes"


def test_a_duels_bound_is_one_sided_at_the_level_its_holm_test_used(analysis):
    a, b = analysis["cells"]
    # search - baseline, Holm over the 2 cells: A's p = 1/256 is judged first, at 0.05 / 2, and rejected;
    # B's (+-3 noise) next, at 0.05.  One-sided upper bound at 0.025 for n = 8: P(T+ <= 3) = 5/256 <= 0.025
    # < 7/256, so the 4th largest Walsh average of d_i = -(1.0 + 0.1 i): -1 - 0.05 (i + j) at i + j = 4
    beats = a["search_beats_baseline"]
    assert beats["level"] == 0.05 / 2 and b["search_beats_baseline"]["level"] == 0.05
    assert beats["upper"] == pytest.approx(-1.2) and beats["percent_upper"] == pytest.approx(1.2 / 11.0)
    # the adaptive duel is a family of one, judged at 0.05: P(T+ <= 5) = 10/256 <= 0.05 < 14/256, the 6th
    # largest Walsh average of d_i = -(0.5 + 0.05 i): -0.5 - 0.025 (i + j), the 6th at i + j = 5
    ad = a["adaptive_beats_parametric"]["adaptive"]
    assert ad["level"] == 0.05 and ad["upper"] == pytest.approx(-0.625)
    # shown exactly when the bound is below 0, in every duel
    duels = [c[q] for c in (a, b) for q in ("search_beats_baseline", "search_beats_random")] + [ad]
    assert all((d["upper"] < 0) == d["significant"] for d in duels)
    text = report.markdown(analysis)
    assert "-1.45 (≤ -1.20 at 0.025; +13.2%, at least +10.9%)" in text


def test_an_extra_searcher_is_compared_with_the_search(analysis):
    a, b = analysis["cells"]
    ad = a["adaptive_beats_parametric"]["adaptive"]
    # d_i = -(0.5 + 0.05 i): HL -0.725, interval [-0.85, -0.6]
    assert (ad["hl"], ad["low"], ad["high"]) == pytest.approx((-0.725, -0.85, -0.6))
    assert ad["answer"] == "yes" and ad["family"] == 1     # the one cell it ran in
    assert "adaptive_beats_parametric" not in b
    assert a["extra_attacks"] == {"adaptive": "policy1"}
    assert a["evaluations"] == {"cma": 3, "random": 2}


def test_the_figure_draws_what_the_table_prints(analysis):
    data = report.figure_data(analysis)["staking"]
    cells = analysis["cells"]
    assert data["share"] == [1 / 25, 3 / 25]
    assert data["loss"] == [c["worst_case_bounded"]["loss"] for c in cells]
    assert data["low"] == [c["worst_case_bounded"]["low"] for c in cells]
    assert data["beyond"] == [c["search_beats_baseline"]["percent"] for c in cells]
    fig = report.figure(analysis)
    loss_ax, beyond_ax = fig.axes
    for ax, (y, lo, hi) in ((loss_ax, ("loss", "low", "high")), (beyond_ax, ("beyond", "beyond_low", "beyond_high"))):
        line, _, (bars,) = ax.containers[0].lines
        np.testing.assert_array_equal(line.get_xdata(), data["share"])
        np.testing.assert_array_equal(line.get_ydata(), data[y])
        lows = [seg[0][1] for seg in bars.get_segments()]
        highs = [seg[1][1] for seg in bars.get_segments()]
        np.testing.assert_allclose(lows, data[lo], rtol=0, atol=1e-12)
        np.testing.assert_allclose(highs, data[hi], rtol=0, atol=1e-12)
    assert [ln.get_ydata()[0] for ln in loss_ax.lines if ln.get_linestyle() == "--"] == [0.10]  # the margin
    md = report.markdown(analysis)
    rows = [line for line in md.splitlines() if line.startswith("| staking |")]
    for row, c in zip(rows, cells):
        b = c["worst_case_bounded"]
        assert f"{b['loss']:.1%} [{b['low']:.1%}, {b['high']:.1%}]" in row
        assert f"{c['search_beats_baseline']['percent']:+.1%}" in row


def test_holm_families_follow_the_declared_family():
    qs = {**QUESTIONS, "search_beats_baseline": {**QUESTIONS["search_beats_baseline"], "family": "byzantines"}}
    cells = report.analyse(study(qs), [A, B])["cells"]
    assert [c["search_beats_baseline"]["family"] for c in cells] == [1, 1]
    assert cells[0]["search_beats_baseline"]["p_adjusted"] == cells[0]["search_beats_baseline"]["p"]
    assert [c["search_beats_random"]["family"] for c in cells] == [2, 2]
    with pytest.raises(ArgumentError, match="family 'robots'"):
        report.analyse(study({**QUESTIONS, "search_beats_random": {"family": "robots"}}), [A, B])


def test_the_objective_liar_wealth_compares_the_liars_wealth():
    # items equal everywhere; the search's liars gain 0.01 i more wealth share than the baseline's
    flat = np.full(N, 9.0)
    cell = search("outlier", 3, worst=flat, base=flat, rand=flat,
                  wealth={"cma_best": 0.3 + 0.01 * IDX, "base_best": np.full(N, 0.3), "rnd_best": np.full(N, 0.3)})
    c = report.analyse(study(objective="liar_wealth"), [cell])["cells"][0]
    assert c["search_beats_baseline"]["hl"] == pytest.approx(-0.045) and c["search_beats_baseline"]["answer"] == "yes"
    assert c["worst_case_bounded"]["loss"] == pytest.approx(0.1)   # the loss is always in items: 1 - 9 / 10


def test_the_loss_is_the_worst_roles_attack():
    # the best baseline is the worst attack here: 9 items on every seed against 10, a loss of 10 %
    cell = search("theta20", 8, worst=np.full(N, 9.5), base=np.full(N, 9.0), rand=np.full(N, 9.8))
    cell.chosen["worst"] = "base_best"
    c = report.analyse(study(), [cell])["cells"][0]
    assert c["worst_case_bounded"]["loss"] == pytest.approx(0.1)
    assert c["medians"]["worst"] == 9.0 and c["chosen"]["worst"] == "base_best"
    assert c["worst"]["role"] == "baseline" and c["more_damaging_than_search"] == ["baseline"]


def test_a_reference_with_no_items_leaves_the_loss_undefined():
    """Runs too short to count items: the per-seed loss 1 - x / 0 is undefined; that cell is answered
    "inconclusive" with a note and left out of the Holm family, the other cell keeps its answer."""
    empty = search("outlier", 1, worst=np.zeros(N), base=np.zeros(N), rand=np.zeros(N))
    empty.confirmation.loc[empty.confirmation.attack == "truthful", "items"] = [0.0, 1.0] * (N // 2)
    plain = search("staking", 1, worst=W_A, base=W_A + 1.0 + 0.1 * IDX, rand=W_A - 0.01 * IDX)
    a = report.analyse(study(), [empty, plain])
    undefined, fine = a["cells"]
    assert undefined["worst_case_bounded"]["answer"] == "inconclusive"
    assert "no items on 4 of 8 seeds" in undefined["worst_case_bounded"]["note"]
    assert fine["worst_case_bounded"]["level_within"] == 0.05 and fine["worst_case_bounded"]["answer"] == "yes"
    md = report.markdown(a)
    assert "| outlier | 1 | 8 | 0.50 | – | undefined | inconclusive |" in md
    assert "- outlier, 1: the truthful reference collected no items on 4 of 8 seeds" in md
    # d = 0 on every seed: no bound; medians 0: no share
    assert "| +0.00 (unbounded at 0.05; share undefined) | inconclusive (power 0.00) |" in md
    assert report.figure(a) is not None


def test_confirmation_runs_must_pair(analysis):
    bad = search("outlier", 1, worst=W_A, base=W_A, rand=W_A)
    bad.confirmation = bad.confirmation.drop(index=3)     # cma_best's run 3
    with pytest.raises(ArgumentError, match="'cma_best'.*missing \\[3\\]"):
        report.analyse(study(), [bad])
    assert analysis["size_note"] == ""
    short = report.analyse(SimpleNamespace(**{**vars(study()), "settings": Settings("items", 16)}), [A])
    assert short["size_note"] == "answered with 8 runs per condition, not the 16 declared"


def test_write_gives_strict_json_markdown_and_the_figure(analysis, tmp_path):
    paths = report.write(tmp_path, analysis, reduced="one cell", steps=2500, transitory=0,
                         provenance={"questions commit": "abc123"},
                         header={"commit": "c0ffee", "tree_clean": False, "questions_commit": "abc123",
                                 "validation": {"search": 0.9, "random": 0.25}})
    assert [p.name for p in paths] == ["report.json", "report.md", "loss.png"]

    def refuse(name):
        raise ValueError(name)

    data = json.loads(paths[0].read_text(), parse_constant=refuse)  # no NaN or Infinity
    assert data["cells"][0]["worst_case_bounded"]["loss"] == pytest.approx(0.1175)
    assert list(data)[:4] == ["commit", "tree_clean", "questions_commit", "validation"]
    assert (data["commit"], data["questions_commit"], data["validation"]) == ("c0ffee", "abc123",
                                                                               {"search": 0.9, "random": 0.25})
    c = data["cells"][0]
    assert (c["defence"], c["byzantines"], c["bounded"]) == ("staking", 1, "inconclusive")
    assert c["worst"]["role"] == "adaptive" and set(c["roles"]["search"]) == {"attack", "loss", "interval"}
    md = paths[1].read_text()
    assert "REDUCED RUN (one cell)" in md and "questions commit: abc123" in md
    assert "All cells: 4160 runs" in md   # (2048 + 32) x 2
    assert "| staking | 1 | 8 | 10.00 | adaptive: policy1 | 11.8% [" in md
    assert "commit `c0ffee` (MODIFIED tree" in md and "search 90%, random 25%" in md
    assert "(evaluations: cma 3, random 2)" in md
    few = search("outlier", 1, worst=W_A[:5], base=W_A[:5], rand=W_A[:5])
    few.confirmation = few.confirmation[few.confirmation.run < 5]
    one = report.analyse(study(), [few])["cells"][0]
    assert math.isinf(one["worst_case_bounded"]["low"])   # 5 pairs bound no 95 % interval
    assert "unbounded" in report.markdown(report.analyse(study(), [few]))


def test_a_second_confirmed_baseline_can_be_the_worst_case():
    """The race's second baseline (confirmed with confirm_top 2) loses 34 % where the selection's pick
    loses 24 %: the worst case is the second one, and it is confirmed more damaging than the search's."""
    cell = search("theta20", 3, worst=np.full(N, 8.0) - 0.01 * IDX, base=np.full(N, 7.6) - 0.01 * IDX,
                  rand=np.full(N, 9.0) - 0.01 * IDX)
    extra = frame({"base_two": np.full(N, 6.6) - 0.01 * IDX})
    cell.confirmation = pd.concat([cell.confirmation, extra], ignore_index=True)
    cell.chosen["baseline_2"] = "base_two"
    c = report.analyse(study(), [cell])["cells"][0]
    # per-seed loss 1 - (6.6 - 0.01 i) / 10 = 0.34 + 0.001 i: Walsh median 0.34 + 0.0045
    assert c["worst"] == {"role": "baseline_2", "loss": pytest.approx(0.3445)}
    assert c["roles"]["baseline_2"]["attack"] == "base_two" and c["bounded"] == "no"
    assert set(c["more_damaging_than_search"]) == {"baseline", "baseline_2"}
