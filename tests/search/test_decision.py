"""The worst case decided over every confirmed attack (``search.decision``), against tables computed by
hand: Holm's step-down with the level each hypothesis was judged at, "within the margin" by
intersection-union (every attack within), "beyond" by Holm over cells x attacks, the worst case the most
damaging attack, and each interval one-sided at its test's level."""
import numpy as np
import pytest

from infomarket.search import decision

IDX = np.arange(1, 9)  # 8 confirmation seeds


def test_holm_levels_by_hand():
    # sorted 0.01 < 0.05/3 rejected at 1/60; 0.03 >= 0.05/2: stop, every other judged at 0.025
    assert decision.holm_levels([0.01, 0.04, 0.03], 0.05) == ([True, False, False],
                                                             [pytest.approx(0.05 / 3), 0.025, 0.025])
    # 0.001 < 1/60, 0.02 < 0.025, 0.04 < 0.05: all rejected, each at its own step
    rej, lev = decision.holm_levels([0.04, 0.001, 0.02], 0.05)
    assert rej == [True, True, True] and lev == pytest.approx([0.05, 0.05 / 3, 0.025])


def test_one_sided_bounds_by_hand():
    # d = 1, 2, 4 ... 128: Walsh averages from the bottom 1, 1.5, 2, 2.5 ..., from the top 128, 96, 80, 72 ...
    # Signed-rank null of 8: P(T+ <= 2) = 3/256 <= 1/60 < P(T+ <= 3) = 5/256 <= 0.025, so at level 1/60 the
    # bounds are the 3rd smallest and 3rd largest (2, 80), at 0.025 the 4th (2.5, 72)
    d = 2.0 ** (IDX - 1)
    assert decision.bound(d, 0.05 / 3, "lower") == 2.0 and decision.bound(d, 0.05 / 3, "upper") == 80.0
    assert decision.bound(d, 0.025, "lower") == 2.5 and decision.bound(d, 0.025, "upper") == 72.0


# Two cells of one family, two confirmed attacks each, margin 10 %:
#   cell 0: a = 0.01 i (every seed within: p_within 1/256), b = 0.05 + 0.001 i (within: 1/256)
#   cell 1: a = 0.20 + 0.01 i (every seed beyond: p_beyond 1/256), b = 0.01 i (within)
# intersection-union p: cell 0 max(1/256, 1/256) = 1/256, cell 1 max(1, 1/256) = 1; Holm over the 2 cells:
# 1/256 < 0.025 (cell 0 "within", judged at 0.025), then 1 >= 0.05: stop (cell 1 judged at 0.05).
# "Beyond" over the 4 (cell, attack): 1/256 < 0.0125 (cell 1's a, judged at 0.0125), then 1 >= 0.05/3: stop.
LOSSES = [{"a": 0.01 * IDX, "b": 0.05 + 0.001 * IDX}, {"a": 0.20 + 0.01 * IDX, "b": 0.01 * IDX}]


def test_within_by_intersection_union_beyond_by_holm_over_cells_and_attacks():
    c0, c1 = decision.bounded(LOSSES, [[0, 1]], 0.10, 0.05)
    assert (c0["answer"], c1["answer"]) == ("yes", "no")
    assert c0["p_within"] == pytest.approx(1 / 256) and c0["level_within"] == 0.025
    assert c1["level_within"] == 0.05 and c1["roles"]["a"]["beyond"] and not c1["roles"]["b"]["beyond"]
    assert c1["roles"]["a"]["level_beyond"] == 0.0125
    assert c0["roles"]["b"]["level_beyond"] == pytest.approx(0.05 / 3)
    # the worst case: the attack with the larger Hodges-Lehmann loss (Walsh median of i: 4.5)
    assert c0["worst"] == {"role": "b", "loss": pytest.approx(0.0545)}
    assert c1["worst"] == {"role": "a", "loss": pytest.approx(0.245)}
    # cell 0's b: lower bound at 1/60 (3rd smallest Walsh average of i: 2), upper at 0.025 (4th largest: 7)
    assert c0["roles"]["b"]["interval"] == pytest.approx([0.052, 0.057])


def test_one_attack_not_shown_within_keeps_the_cell_from_yes():
    """The search's attack is within, the random search's straddles the margin: not "yes" (the selection's
    pick alone would have said yes), and not "no" either."""
    straddle = 0.1 + 0.02 * (-1.0) ** IDX * IDX  # above on even seeds, below on odd ones
    (c,) = decision.bounded([{"search": 0.01 * IDX, "random": straddle}], [[0]], 0.10, 0.05)
    assert c["answer"] == "inconclusive"
    assert c["worst"]["role"] == "random"


def test_a_more_damaging_role_than_the_search_is_named():
    got = dict(decision.dominated({"search": 9.0 + 0.0 * IDX, "baseline": 8.0 + 0.01 * IDX, "random": 9.5 + 0 * IDX}))
    assert got["baseline"] == pytest.approx(1 / 256) and got["random"] > 0.5
