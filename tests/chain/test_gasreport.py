"""The gas report (infomarket.chain.gasreport): a deposit of any length fits block by block."""
from __future__ import annotations

from infomarket.chain.gasreport import TX_LIMIT, GasRow, measure, render
from infomarket.chain.market import connect


def test_a_256_record_worst_case_deposit_splits_into_transactions_that_each_fit_a_block():
    """Outlier weighting with staking, every pair of the 256 vectors similar: the deposit takes
    several transactions (the old contract needed 16M gas in one), none near a 30M block. On revm
    only: py-evm takes two minutes for these 256 reveals (test_market checks the split on both)."""
    (row,) = measure("outlier + staking", (256,), trips=1, backend=connect(backend="revm"))
    assert row.n == 256
    assert row.transactions > 1
    assert row.largest_tx < TX_LIMIT
    assert 21_000 < row.reveal_mean <= row.reveal_max < 250_000


def test_report_lists_every_size_per_scheme_and_the_largest_transaction():
    rows = [GasRow("delayed", 1, 90_000.4, 100_000, 60_000, 50_000, 1, 60_000),
            GasRow("delayed", 64, 80_000.0, 100_000, 500_000, 480_000, 3, 300_000)]
    text = render(rows)
    assert "| 1 | 90,000 | 100,000 | 60,000 | 50,000 | 1 | 60,000 |" in text
    assert "| 64 | 80,000 | 100,000 | 500,000 | 480,000 | 3 | 300,000 |" in text
    assert "Largest single transaction measured: 300,000 gas (delayed, n = 64)" in text
