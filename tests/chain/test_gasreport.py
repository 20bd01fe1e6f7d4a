"""The gas report (infomarket.chain.gasreport): the issue's ceiling for buyItem at 64 transactions."""
from __future__ import annotations

from infomarket.chain.gasreport import BUY_ITEM_LIMIT, GasRow, measure, render


def test_buy_item_settles_64_transactions_under_five_million_gas(w3):
    """Worst case: outlier weighting with staking, every pair of the 64 directions similar."""
    (row,) = measure("outlier + staking", (64,), trips=1, w3=w3)
    assert row.n == 64
    assert row.buy_first < BUY_ITEM_LIMIT
    assert 21_000 < row.reveal_mean <= row.reveal_max < 200_000


def test_report_lists_every_size_per_scheme_and_the_largest_buy():
    rows = [GasRow("delayed", 1, 90_000.4, 100_000, 60_000, 50_000),
            GasRow("delayed", 64, 80_000.0, 100_000, 500_000, 480_000)]
    text = render(rows)
    assert "| 1 | 90,000 | 100,000 | 60,000 | 50,000 |" in text
    assert "| 64 | 80,000 | 100,000 | 500,000 | 480,000 |" in text
    assert "Largest buyItem measured: 500,000 gas (delayed, n = 64)" in text
