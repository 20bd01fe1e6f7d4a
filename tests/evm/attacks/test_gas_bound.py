"""No call takes more than the declared gas bound, even at its worst.

The exploit: the bound (6 M gas a call) was measured with 16 sellers; under `outlier_distinct`, 512
distinct, similar sellers skip no comparison, and `buyItem` took 6.5 M gas at the default batch of 48
(7.7 M at the batch of 64 the contract allowed). Now a distinct-seller weighing costs more units of the
batch (ceil(m / 40) a record instead of ceil(m / 64)), the batch is at most 48, and docs/gas.md
measures every scheme at 512 distinct sellers (and `outlier_distinct` at 480, its worst size).
"""
from __future__ import annotations

import re
from pathlib import Path

from infomarket.evm.gasreport import MORE_SCHEMES, SCHEMES, gas_backend, worst_call
from infomarket.evm.market import DECLARED_MAX_TX_GAS

from .helpers import sell

REPORT = Path(__file__).resolve().parents[3] / "docs" / "gas.md"
BOUND_ROW = re.compile(r"^\| ([a-z_ +]+) \| (\d+) \| (\d+) \| ([\d,]+) \| ([\d,]+) \| ([\d,]+) \| (\d+) "
                       r"\| ([\d,]+) \|$")


def test_512_distinct_similar_sellers_stay_under_the_bound_under_outlier_distinct():
    worst = worst_call("outlier_distinct + staking", 512, sellers=512, backend=gas_backend("revm"))
    assert worst.buy_item > 3_000_000 and worst.settle > 3_000_000  # every weighing call loads 512 records
    assert worst.largest < DECLARED_MAX_TX_GAS


def test_512_distinct_similar_sellers_stay_under_the_bound_under_outlier_capped():
    """OutlierCapped weighs as Outlier among the counted records (a void one is compared with nothing), so
    its worst round trip has every record counted: 512 distinct sellers, one record each."""
    worst = worst_call("capped_outlier + staking", 512, sellers=512, backend=gas_backend("revm"))
    assert worst.buy_item > 3_000_000 and worst.settle > 3_000_000  # every weighing call loads 512 records
    assert worst.largest < DECLARED_MAX_TX_GAS


def test_the_report_measures_every_scheme_at_its_worst_and_under_the_bound():
    rows = {}
    for line in REPORT.read_text().splitlines():
        if found := BOUND_ROW.match(line):
            scheme, n, sellers, *gas = found.groups()
            rows[scheme] = (int(n), int(sellers), [int(g.replace(",", "")) for g in gas])
    assert set(SCHEMES) <= set(rows) <= set(SCHEMES) | set(MORE_SCHEMES)  # the report's, and the other schemes'
    for scheme, (n, sellers, (reveal, buy, settle, calls, total)) in rows.items():
        assert (n, sellers) == (512, 512), scheme
        assert max(reveal, buy, settle) < DECLARED_MAX_TX_GAS, scheme
        assert calls >= 1 and total >= buy + settle * (calls > 1), scheme
    assert f"declared bound (`DECLARED_MAX_TX_GAS`): {DECLARED_MAX_TX_GAS:,}." in REPORT.read_text()


def test_a_distinct_seller_weighing_costs_more_of_the_batch(make_market, robots):
    """41 live records: weighing one costs ceil(41 / 40) = 2 units under outlier_distinct (ceil(41 / 64)
    = 1 under outlier), so a batch of 4 weighs 2 records (4 under outlier)."""
    remaining = {}
    for scheme in ("outlier", "outlier_distinct"):
        market = make_market(scheme, stake=0.0, settle_batch=4)
        buyer = robots[0]
        for k in range(41):
            sell(market, robots[1 + k % 7], buyer, 10.0 + k % 5, age=k)
        market.buy_item(buyer.address)
        remaining[scheme] = market.pending_settlement(buyer.address)
    assert remaining == {"outlier": (True, 1, 41 - 4), "outlier_distinct": (True, 1, 41 - 2)}
