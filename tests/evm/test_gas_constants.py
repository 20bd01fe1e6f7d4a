"""The chain model's gas (infomarket.ledger.gas) is docs/gas.md's: every constant equals the report's
figure, so a regenerated report (``make gas``) whose constants were not pasted again fails here instead of
going stale silently.  The report is read by this file's own parser, not by the report's code."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from infomarket.evm.gasreport import GasRow, WorstCall, constants, parse, render
from infomarket.ledger import gas

REPORT = Path(__file__).resolve().parents[2] / "docs" / "gas.md"
ROW = re.compile(r"^\| (\d+) \| ([\d,]+) \| [\d,]+ \| [\d,]+ \| ([\d,]+) \| \d+ \| [\d,]+ \|$")


def _report() -> dict[str, dict[int, tuple[int, int]]]:
    """scheme heading -> n -> (reveal, mean; deposit, later trips), from docs/gas.md's per-scheme tables."""
    tables, heading = {}, None
    for line in REPORT.read_text().splitlines():
        if line.startswith("## "):
            heading = line[3:].strip()
        elif heading and (m := ROW.match(line)):
            n, reveal, later = (int(g.replace(",", "")) for g in m.groups())
            tables.setdefault(heading, {})[n] = (reveal, later)
    return tables


def test_the_constants_are_the_reports_figures():
    tables = _report()
    assert set(tables) == set(gas.GAS_REVEAL) == set(gas.GAS_DEPOSIT)
    for scheme, table in tables.items():
        assert tuple(table) == gas.GAS_DEPOSIT_N, scheme
        assert gas.GAS_REVEAL[scheme] == table[16][0], scheme
        assert gas.GAS_DEPOSIT[scheme] == tuple(later for _, later in table.values()), scheme


def test_the_table_reaches_the_contracts_bound_of_live_records():
    assert gas.GAS_DEPOSIT_N[-1] == 512 and gas.GAS_DEPOSIT_N[:4] == (1, 4, 16, 64)


@pytest.mark.parametrize("scheme, stake, heading", [
    ("delayed", 0.0, "delayed"), ("outlier", 0.0, "outlier"), ("outlier", 0.04, "outlier + staking"),
    ("outlier_distinct", 0.0, "outlier_distinct"), ("outlier_distinct", 0.04, "outlier_distinct + staking"),
    ("delayed", 0.04, "delayed"),        # measured without a stake; as before
    ("weighted_user_scheme", 0.0, "outlier"), ("weighted_user_scheme", 0.04, "outlier + staking")])
def test_each_scheme_is_charged_its_own_table(scheme, stake, heading):
    table = _report()[heading]
    reveal, deposit = gas.gas_schedule(scheme, stake)
    assert reveal == table[16][0]
    assert deposit == tuple(later for _, later in table.values())


def test_the_deposit_rule_interpolates_and_stops_at_the_bound():
    """outlier + staking: n = 384 is halfway between n = 256 (80 253 716) and n = 512 (419 152 439):
    249 703 077.5; beyond 512 (the contract refuses the reveals) the 512 figure; n = 0 the n = 1 figure;
    n = 10 halfway between n = 4 (217 803) and n = 16 (549 726)."""
    xs = np.asarray(gas.GAS_DEPOSIT_N, float)
    ys = np.asarray(gas.GAS_DEPOSIT["outlier + staking"], float)
    assert gas.table_gas(xs, ys, 384.0) == pytest.approx(249_703_077.5)
    assert gas.table_gas(xs, ys, 512.0) == 419_152_439
    assert gas.table_gas(xs, ys, 2000.0) == 419_152_439
    assert gas.table_gas(xs, ys, 0.0) == 167_885
    assert gas.table_gas(xs, ys, 10.0) == pytest.approx((217_803 + 549_726) / 2)


def test_the_report_prints_the_constants_it_was_rendered_from():
    rows = [GasRow(s, n, 100_000.0 + n + k, 150_000, 9, 10 * n + k, 1, 9)
            for k, s in ((0, "delayed"), (7, "outlier + staking")) for n in (1, 16)]
    text = render(rows, [WorstCall("outlier", 512, 512, 1, 2, 3, 4, 5)])
    assert parse(text) == rows
    assert constants(parse(text)) == "\n".join([
        "GAS_REVEAL = {", '    "delayed": 100_016,', '    "outlier + staking": 100_023,', "}",
        "GAS_DEPOSIT_N = (1, 16)", "GAS_DEPOSIT = {", '    "delayed": (10, 160),',
        '    "outlier + staking": (17, 167),', "}"])


def test_constants_from_a_missing_or_tableless_report_is_a_clear_error(tmp_path, capsys):
    from infomarket.evm.gasreport import main

    assert main(["--constants", "--out", str(tmp_path / "none.md")]) == 2
    assert "none.md: no such report" in capsys.readouterr().err
    (tmp_path / "empty.md").write_text("# Gas\n\nnothing measured\n")
    assert main(["--constants", "--out", str(tmp_path / "empty.md")]) == 2
    assert "empty.md: no gas table in it" in capsys.readouterr().err
    rows = [GasRow("delayed", 1, 1.0, 1, 1, 1, 1, 1), GasRow("outlier", 4, 1.0, 1, 1, 1, 1, 1)]
    (tmp_path / "uneven.md").write_text(render(rows, []))
    assert main(["--constants", "--out", str(tmp_path / "uneven.md")]) == 2
    assert "measured at different sizes" in capsys.readouterr().err
    (tmp_path / "no16.md").write_text(render(rows[:1], []))
    assert main(["--constants", "--out", str(tmp_path / "no16.md")]) == 2
    assert "no n = 16 row" in capsys.readouterr().err
    assert not (tmp_path / "none.md").exists()
