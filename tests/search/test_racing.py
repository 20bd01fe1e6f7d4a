"""Successive halving: stages add runs to the attacks still in contention, each group keeps its best."""
import numpy as np

from infomarket.search.racing import race, survivors


def test_each_stage_adds_runs_only_to_the_attacks_kept():
    # attack "aK" has loss K on every run: the ranking is known by construction
    calls = []

    def evaluate(labels, runs):
        calls.append((sorted(labels), runs))
        return {a: np.full(runs, float(a[1:])) for a in labels}

    groups = {"x": ["a5", "a1", "a4", "a2", "a3"], "y": ["a9"]}
    out = race(groups, (2, 4, 8), 0.5, evaluate)
    # 5 attacks keep ceil(2.5) = 3, then 3 keep 2; a group of one keeps it
    assert calls == [(["a1", "a2", "a3", "a4", "a5", "a9"], 2), (["a1", "a2", "a3", "a9"], 4), (["a1", "a2", "a9"], 8)]
    assert out.ranking == {"x": ["a1", "a2"], "y": ["a9"]}
    assert out.dropped == {"a4": 0, "a5": 0, "a3": 1}


def test_a_later_stage_can_overturn_the_first():
    # "lucky" looks best on the first 2 runs, "good" is best over 4
    table = {"lucky": [0.0, 0.0, 9.0, 9.0], "good": [1.0, 1.0, 1.0, 1.0], "bad": [5.0, 5.0, 5.0, 5.0]}
    out = race({"g": ["lucky", "good", "bad"]}, (2, 4), 0.5, lambda labels, runs: {a: np.array(table[a][:runs])
                                                                                    for a in labels})
    assert out.ranking["g"] == ["good", "lucky"] and out.dropped == {"bad": 0}


def test_survivors_keep_at_least_two():
    assert [survivors(n, 0.5) for n in (1, 2, 3, 4, 5, 9)] == [1, 2, 2, 2, 3, 5]
    assert survivors(10, 0.1) == 2
