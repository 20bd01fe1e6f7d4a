"""The defence search's answers from hand-built confirmation runs, and its frontier rules."""
import math

import numpy as np
import pandas as pd
import pytest

from infomarket.config import load_experiment
from infomarket.defence import report, study
from infomarket.defence.driver import Judged, Result, frontier, pareto, ratio_loss
from infomarket.defence.families import EXISTING, Candidate

RUNS = 12
# per-seed values spread symmetrically about their centre, so the Hodges-Lehmann estimate is the centre
SPREAD = np.tile([-0.01, 0.0, 0.01], RUNS // 3)


def _judged(label, origin="design", cost=0.0, loss=0.0):
    family = EXISTING if origin == "existing" else "robust_median"
    return Judged(Candidate(label, family, {} if origin == "existing" else {"vectors": 5.0}, origin=origin),
                  cost, {1: loss, 3: loss, 8: loss}, {b: {"worst": {}, "reference": {}} for b in (1, 3, 8)})


def _result(spec: dict[str, tuple[float, float]], judged: list[Judged]) -> Result:
    """Confirmation runs where candidate ``label`` costs ``cost`` and loses ``loss`` per seed (plus SPREAD)."""
    cost_rows, attack_rows = [], []
    undefended = np.full(RUNS, 10.0)
    for label, (cost, loss) in spec.items():
        cost_rows.append(pd.DataFrame({"label": label, "run": np.arange(RUNS),
                                       "items": undefended * (1 - cost - SPREAD), "undefended": undefended}))
        for b in (1, 3, 8):
            ref = np.full(RUNS, 8.0)
            attack_rows.append(pd.DataFrame({"label": label, "byzantines": b, "run": np.arange(RUNS),
                                             "worst": ref * (1 - loss - SPREAD), "reference": ref}))
    return Result(judged, list(spec), pd.concat(cost_rows, ignore_index=True),
                  pd.concat(attack_rows, ignore_index=True))


@pytest.fixture(scope="module")
def st():
    return study.load(load_experiment("attack_search"))


def test_a_cheap_bounded_defence_is_yes_and_a_broken_one_is_no(st):
    judged = [_judged("good", cost=0.01, loss=0.04), _judged("broken", cost=0.01, loss=0.5),
              _judged("staking", "existing", cost=0.0, loss=0.35)]
    a = report.analyse(st, _result({"staking": (0.0, 0.35), "good": (0.01, 0.04), "broken": (0.01, 0.5)}, judged))
    rows = {r["label"]: r for r in a["confirmed"]}
    # by hand: 12 seeds, every per-seed value 2 points or more inside the margin, so every signed rank is on
    # one side: one-sided p = 2^-12, Holm over 3 candidates at most 3 x 2^-12 < 0.05
    assert rows["good"]["answer"] == "yes" and rows["broken"]["answer"] == "no"
    assert rows["staking"]["answer"] == "no"  # its loss is shown beyond 10 %
    assert rows["good"]["cost"]["hl"] == pytest.approx(0.01) and rows["good"]["loss"]["3"]["hl"] == pytest.approx(0.04)
    assert rows["broken"]["loss"]["3"]["hl"] == pytest.approx(0.5)
    assert a["bounded_defence"] == {"answer": "yes", "yes": ["good"]}
    e = a["beats_existing"]  # the best new trade (good) against the best existing (staking): 4 % - 35 %
    assert (e["new"], e["existing"], e["answer"]) == ("good", "staking", "yes") and e["hl"] == pytest.approx(-0.31)


def test_costly_defences_make_the_answer_no_and_a_close_call_is_inconclusive(st):
    judged = [_judged("costly", cost=0.2, loss=0.02), _judged("broken", cost=0.0, loss=0.5)]
    a = report.analyse(st, _result({"costly": (0.2, 0.02), "broken": (0.0, 0.5)}, judged))
    assert [r["answer"] for r in a["confirmed"]] == ["no", "no"] and a["bounded_defence"]["answer"] == "no"
    close = report.analyse(st, _result({"near": (0.0, 0.10)}, [_judged("near", loss=0.10)]))
    assert close["confirmed"][0]["answer"] == "inconclusive" and close["bounded_defence"]["answer"] == "inconclusive"


def test_a_reference_that_collected_nothing_leaves_the_loss_undefined(st):
    r = _result({"dead": (0.0, 0.0)}, [_judged("dead")])
    r.attack_runs.loc[(r.attack_runs.byzantines == 3) & (r.attack_runs.run == 4), "reference"] = 0.0
    row = report.analyse(st, r)["confirmed"][0]
    assert math.isnan(row["loss"]["3"]["hl"]) and "undefined" in row["loss"]["3"]["note"]
    assert row["answer"] == "inconclusive"


def test_the_pareto_set_and_the_frontier_by_hand(st):
    a, b, c, d = (_judged("a", cost=0.00, loss=0.40), _judged("b", cost=0.02, loss=0.20),
                  _judged("c", cost=0.03, loss=0.30), _judged("d", cost=0.10, loss=0.10))
    nan = _judged("n", cost=float("nan"), loss=0.0)
    old = _judged("staking", "existing", cost=0.0, loss=0.01)
    assert [j.candidate.label for j in pareto([a, b, c, d, nan], 3)] == ["a", "b", "d"]  # c is beaten by b
    # trade = loss + max(0, cost - 0.05): a 0.40, b 0.20, d 0.15; existing defences are never on it
    assert [j.candidate.label for j in frontier(st, [a, b, c, d, nan, old])] == ["d", "b", "a"]
    assert math.isinf(nan.trade(3, 0.05))


def test_the_search_phase_estimate_is_a_ratio_of_means():
    assert ratio_loss([0.0, 4.0], [2.0, 2.0]) == pytest.approx(0.0)  # per-seed ratios would not be defined
    assert ratio_loss([1.0, 2.0], [4.0, 4.0]) == pytest.approx(1 - 1.5 / 4)
    assert math.isnan(ratio_loss([1.0], [0.0]))


def test_the_figure_draws_exactly_the_table_numbers(st, tmp_path):
    judged = [_judged("good", cost=0.01, loss=0.04), _judged("staking", "existing", cost=0.0, loss=0.35)]
    a = report.analyse(st, _result({"staking": (0.0, 0.35), "good": (0.01, 0.04)}, judged))
    d = report.figure_data(a)
    rows = {r["label"]: r for r in a["confirmed"]}
    for k, lab in enumerate(d["label"]):
        assert d["cost"][k] == rows[lab]["cost"]["hl"] and d["loss"][k] == rows[lab]["loss"]["3"]["hl"]
        assert (d["loss_low"][k], d["loss_high"][k]) == (rows[lab]["loss"]["3"]["low"], rows[lab]["loss"]["3"]["high"])
    g = report.growth_data(a)
    assert g["good"]["loss"] == [rows["good"]["loss"][c]["hl"] for c in ("1", "3", "8")]
    assert g["floor"]["kappa"] == pytest.approx([1 / 23, 3 / 19, 8 / 9]) and g["floor"]["share"] == [0.04, 0.12, 0.32]
    # by hand: the undefended swarm collects 10 per seed, "good" 10 x (0.99 - spread): 0.1 lost per robot
    assert rows["good"]["cost_items"]["hl"] == pytest.approx(0.1)
    paths = report.write(tmp_path, a)
    assert {p.name for p in paths} == {"defence.json", "defence.md", "frontier.png"}
    text = (tmp_path / "defence.md").read_text()
    assert "| good | robust_median | 1.0% [" in text and "| 0.10 [" in text and "**Is there a defence" in text
    # by hand: 5 purchases, 3 of the 24 others lie, so f = 5 x 3 / 24 = 0.625 of n = 6 voices:
    # 0.625 / (6 - 1.25) = 0.132; staking combines no vectors
    assert "| yes | 0.132 | vectors 5 |" in text and "| no | – | – |" in text
