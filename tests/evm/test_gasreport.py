"""The gas report (infomarket.evm.gasreport) and the declared bound, with cold storage (py-evm, and
revm, which charges the same gas)."""
from __future__ import annotations

from dataclasses import replace

from infomarket.evm.gasreport import (CROSS_CHECK_TOLERANCE, GasRow, WorstCall, cross_check, gas_backend, measure,
                                        render, worst_call)
from infomarket.evm.market import DECLARED_MAX_TX_GAS, connect


def test_a_deposit_with_cold_storage_splits_into_calls_under_the_declared_bound():
    """A 64-record worst-case round trip (every pair similar) under outlier_distinct with staking, on
    py-evm (cold storage per transaction): several calls, each under the declared bound. The bound
    itself is measured at 512 records by `make gas` (docs/gas.md), which takes minutes on py-evm."""
    (row,) = measure("outlier_distinct + staking", (64,), trips=1, backend=connect(backend="py-evm"))
    assert row.transactions > 1
    assert row.largest_tx < DECLARED_MAX_TX_GAS
    assert 21_000 < row.reveal_mean <= row.reveal_max < 250_000


def test_the_worst_call_at_a_full_round_trip_is_measured_after_the_reveals():
    # on revm, as `make gas` measures it (revm charges py-evm's gas on large round trips: test_revm_gas.py)
    worst = worst_call("outlier + staking", 80, sellers=80, backend=gas_backend("revm"))
    # 80 records: weighing one costs ceil(80 / 64) = 2 units, so buyItem and the next call each weigh 24;
    # 80 * 2 units of weighing and 80 of payment make 240 units, 5 calls of 48
    assert (worst.n, worst.sellers, worst.calls) == (80, 80, 5)
    assert worst.settle > 21_000 and worst.buy_item > worst.settle / 2
    assert worst.total > worst.buy_item + worst.settle and worst.largest < DECLARED_MAX_TX_GAS


def test_report_lists_every_size_per_scheme_and_the_bound():
    rows = [GasRow("delayed", 1, 90_000.4, 100_000, 60_000, 50_000, 1, 60_000),
            GasRow("delayed", 64, 80_000.0, 100_000, 500_000, 480_000, 3, 300_000)]
    text = render(rows, [WorstCall("outlier", 512, 512, 180_000, 3_000_000, 3_500_000, 96, 300_000_000)])
    assert "| 1 | 90,000 | 100,000 | 60,000 | 50,000 | 1 | 60,000 |" in text
    assert "| 64 | 80,000 | 100,000 | 500,000 | 480,000 | 3 | 300,000 |" in text
    assert "| outlier | 512 | 512 | 180,000 | 3,000,000 | 3,500,000 | 96 | 300,000,000 |" in text
    assert f"Largest single transaction measured: 3,500,000 gas; declared bound (`DECLARED_MAX_TX_GAS`): " \
           f"{DECLARED_MAX_TX_GAS:,}." in text


def test_the_report_on_revm_agrees_with_py_evm_and_the_cross_check_catches_a_difference():
    """The report runs on revm (seconds) and measures its small sizes again on py-evm: the figures agree
    (they differ only by the zero bytes of non-deterministic signatures, 12 gas each); a figure 2 %
    off, or another number of transactions, fails the cross-check."""
    rows = measure("outlier + staking", (1, 4), backend=gas_backend("revm"))
    assert cross_check(rows, (1, 4)) < 0.001
    assert cross_check([replace(rows[0], deposit_later=int(rows[0].deposit_later * 1.02)), rows[1]], (1, 4)) > \
        CROSS_CHECK_TOLERANCE
    assert cross_check([rows[0], replace(rows[1], transactions=rows[1].transactions + 1)], (1, 4)) > \
        CROSS_CHECK_TOLERANCE
