"""The paper's numbers are locked: every shipped paper setup reproduces the digests recorded before
the engine was rewritten (see ``tests/engine/golden.py`` for what is hashed and how to regenerate)."""
import pytest

from . import golden

EXPECTED = golden.load()


@pytest.mark.parametrize("case", golden.cases(full=False), ids=lambda c: c.key)
def test_paper_setups_are_bit_identical(case):
    assert golden.digest(case) == EXPECTED[case.key]


@pytest.mark.slow
@pytest.mark.parametrize("case", [c for c in golden.cases(full=True) if c not in golden.cases(full=False)],
                         ids=lambda c: c.key)
def test_paper_setups_full_length_are_bit_identical(case):
    assert golden.digest(case) == EXPECTED[case.key]
