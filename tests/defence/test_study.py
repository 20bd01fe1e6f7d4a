"""The defence study's declared settings: a bad value is refused naming the key, before any run."""
import pytest

from infomarket.defence.study import settings
from infomarket.errors import UsageError


@pytest.mark.parametrize("value", ["no", 0, 1, None])
def test_every_count_must_be_true_or_false(value):
    with pytest.raises(UsageError, match=r"every_count: true or false is expected"):
        settings({"every_count": value})


def test_every_count_defaults_to_judging_every_count():
    assert settings({}).every_count is True and settings({"every_count": False}).every_count is False
