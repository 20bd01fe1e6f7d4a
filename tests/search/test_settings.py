"""The attack search's declared settings are read by the studies' one parser: a bad value is refused as
an experiment file's is (the source, then one line per key naming what is expected and what was given)."""
import pytest

from infomarket.errors import UsageError
from infomarket.search.study import Learner, Settings, learner, settings

SOURCE = "search settings (questions.toml [search] or an option)"


@pytest.mark.parametrize("table, line", [
    ({"budegt": 3}, "budegt: unknown key; allowed keys here: budget, popsize"),
    ({"race": [8, 4]}, "race: cumulative runs per stage, whole numbers from 2 up, each above the one before "
                       "(e.g. [8, 16, 32]) (got [8, 4])"),
    ({"race": [1, 4]}, "race: cumulative runs per stage"),
    ({"spread": 1.0}, "spread: a share of the budget in [0, 1) is expected (got 1.0)"),
    ({"restarts": 2, "local": 3}, "local: at most as many local restarts as restarts is expected (got 3)"),
    ({"objective": "gold"}, "objective: one of items, liar_wealth is expected (got 'gold')"),
    ({"pool_baselines": 1}, "pool_baselines: true or false is expected (got 1)"),
    ({"seed": -1}, "seed: a whole number of at least 0 is expected (got -1)"),
    ({"keep": 0.0}, "keep: a number in (0, 1] is expected (got 0.0)"),
])
def test_a_bad_setting_is_one_message_naming_the_key(table, line):
    with pytest.raises(UsageError) as err:
        settings(table)
    assert str(err.value).startswith(f"{SOURCE}: invalid settings\n  {line}")


def test_every_bad_setting_is_named_in_the_fields_order():
    with pytest.raises(UsageError) as err:
        settings({"runs": 0, "budget": 0})
    assert str(err.value).splitlines()[1:] == ["  budget: a whole number of at least 1 is expected (got 0)",
                                               "  runs: a whole number of at least 1 is expected (got 0)"]


def test_an_option_overrides_the_table_and_a_small_budget_makes_one_smaller_generation():
    s = settings({"budget": 64, "race": [2, 4]}, {"budget": 3, "runs": None})
    assert s == Settings(budget=3, popsize=3, race=(2, 4)) and s.generations == 1


@pytest.mark.parametrize("table, line", [
    ({"budget": -1}, "budget: a whole number of at least 0 is expected (got -1)"),
    ({"pairs": 2.5}, "pairs: a whole number of at least 1 is expected (got 2.5)"),
    ({"sigma": float("inf")}, "sigma: a finite number above 0 is expected (got inf)"),
    ({"lr": 0}, "lr: a finite number above 0 is expected (got 0)"),
    ({"rate": 0.1}, "rate: unknown key; allowed keys here: budget, pairs, runs, sigma, lr"),
])
def test_the_adaptive_attackers_training_is_read_by_the_same_parser(table, line):
    with pytest.raises(UsageError) as err:
        learner(table)
    assert str(err.value) == f"questions.toml [adaptive] or an option: invalid settings\n  {line}"


def test_the_adaptive_budget_option_overrides_the_declared_one():
    assert learner({"budget": 48, "sigma": 0.1}, {"budget": None}) == Learner(48, sigma=0.1)
    assert learner({"budget": 48}, {"budget": 0}).budget == 0
