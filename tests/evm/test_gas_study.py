"""The chain study's gas question after the gas table became cold (chain_questions.toml, [amendment_gas]):
its prices keep the declared ratios with the model's reveal gas, the shipped sweeps run exactly those
prices under the amended labels, the answer reads those labels, and a new store records the question file."""
from __future__ import annotations

import math

import pytest

from infomarket.analysis import chain_study as cs
from infomarket.analysis.declared import DECLARED, check, status_of
from infomarket.config.load import load_experiment
from infomarket.ledger.gas import GAS_REVEAL
from infomarket.runner.plan import conditions
from infomarket.store import Store

DECL = cs.declaration()
AMENDED = DECL["amendment_gas"]
STAKE = 0.04


def _three_digits(x: float) -> float:
    return float(f"{x:.3g}")


def test_the_amended_prices_keep_the_declared_ratios_with_the_reveal_gas_they_were_run_with():
    """gas_price = ratio x 0.04 / the reveal gas with staking the study ran with (126 228, recorded in
    [amendment_gas]), to 3 digits: e.g. 0.3 x 0.04 / 126 228 = 9.5066e-8 -> 9.51e-8 (the stale table's
    94 038 gave 1.28e-7).  The audited contract's reveal costs more since (128 652 with staking: roles and
    the pause flag; 128 645 with the bond and the late-deposit rule), so the same prices now stand for
    ratios 128 645 / 126 228 = 1.0191 times the declared ones; the questions file records both
    deviations."""
    assert AMENDED["gas_ratio"] == DECL["study"]["gas_ratio"]  # the declared ratios are kept
    assert AMENDED["reveal_gas"] == 126_228
    assert AMENDED["gas_price"][3] == 9.51e-8
    for ratio, price in zip(AMENDED["gas_ratio"], AMENDED["gas_price"]):
        assert price == _three_digits(ratio * STAKE / AMENDED["reveal_gas"]), ratio
    assert GAS_REVEAL["outlier + staking"] / AMENDED["reveal_gas"] == pytest.approx(1.0191, abs=1e-4)
    assert any("128 652" in d["what"] and "breaks_gas" in d["questions"] for d in DECL["deviations"])
    assert any("128 645" in d["what"] and "breaks_gas" in d["questions"] for d in DECL["deviations"])


def test_the_shipped_sweeps_run_the_amended_gas_conditions():
    for name in ("chain_sweep", "chain_fig7_sweep"):
        gas = {}
        for c in conditions(load_experiment(name)):
            if c.config.chain.gas_price > 0:
                gas[c.keys["chain"]] = c.config.chain.gas_price
        want = {AMENDED["label"].format(f"{r:g}"): p for r, p in zip(AMENDED["gas_ratio"], AMENDED["gas_price"])
                if r > 0}
        assert gas.keys() == want.keys(), name
        assert all(math.isclose(gas[k], want[k], rel_tol=1e-12) for k in want), name


def test_the_gas_answer_reads_the_amended_conditions_only():
    labels = [label for _, label in cs.axis_values(DECL, "gas")]
    assert labels == ["toychain", "coldgas_0.01", "coldgas_0.1", "coldgas_0.3", "coldgas_1", "coldgas_3"]
    stale = {k: v for k, v in DECL.items() if k != "amendment_gas"}
    assert [label for _, label in cs.axis_values(stale, "gas")][1:] == ["gas_0.01", "gas_0.1", "gas_0.3", "gas_1",
                                                                         "gas_3"]


def test_a_new_store_records_the_chain_questions(tmp_path):
    store = Store(tmp_path / "s").create()
    rec = store.declarations()
    assert {"questions.breaks_gas", "amendment_gas"} <= set(rec["chain_questions.toml"]["sections"])
    locks = check(rec, {"chain_questions.toml": cs.QUESTIONS})
    assert status_of(locks, "chain_questions.toml", "questions.breaks_gas") == DECLARED
