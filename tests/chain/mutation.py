"""Mutation check for the attack tests: remove each of the contract's checks in turn and show that the
test guarding it fails.

Each mutant is a copy of contracts/InformationMarket.sol with one ``if (<check>) revert ...`` turned into
``if (false) revert ...``, compiled by the pinned solc-js into a temporary artifact, against which
tests/chain/test_attacks.py runs (through ``INFOMARKET_CHAIN_ARTIFACT``, see conftest.py). It needs
Node and takes about a minute and a half, so it is a script, not part of the test suite:

    .venv/bin/python tests/chain/mutation.py

Exit status 0 when every mutant is caught (its tests fail) and the unpatched copy passes them.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "contracts" / "InformationMarket.sol"
COMPILER = ROOT / "tools" / "solc" / "compile.js"
ATTACKS = ROOT / "tests" / "chain" / "test_attacks.py"

#: (the check removed, the condition's text in the source, names of the tests that must then fail)
MUTANTS = [
    ("current block <= max block", "block.number > offer.maxBlock",
     ["test_reveal_after_the_max_block"]),
    ("buyer signature valid", "recovered == address(0) || recovered != lc.buyer",
     ["test_forged_buyer_signature", "test_a_signature_for_another_market", "test_a_signature_for_another_chain"]),
    ("tuple never used", "_revealed[key]",
     ["test_the_same_light_contract"]),
    ("caller is the seller", "msg.sender != seller",
     ["test_a_third_party_cannot"]),
    ("information matches hash", "revealed != offer.pathHash",
     ["test_revealed_information_must_match"]),
    ("seller can lock the stake", "balance < stake_",
     ["test_a_seller_that_cannot_lock_the_stake"]),
    ("caller is the market", "msg.sender != _market",
     ["test_only_the_market_account"]),
    ("signature s is low", "uint256(lc.s) > _HALF_ORDER",
     ["test_a_malleated_high_s_signature"]),
]


def compile_variant(source: str, workdir: Path, name: str) -> Path:
    sol, out = workdir / f"{name}.sol", workdir / f"{name}.json"
    sol.write_text(source)
    subprocess.run(["node", str(COMPILER), "--source", str(sol), "--out", str(out), "--allow-warnings"],
                   check=True, capture_output=True, text=True)
    return out


def run_tests(artifact: Path, selected: list[str]) -> tuple[int, str]:
    """Run the attack tests whose names start with one of ``selected``; (exit code, summary line)."""
    env = dict(os.environ, INFOMARKET_CHAIN_ARTIFACT=str(artifact))
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(ATTACKS),
                           "-k", " or ".join(selected)],
                          env=env, capture_output=True, text=True, cwd=ROOT)
    summary = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else done.stderr.strip()[-200:]
    return done.returncode, summary


def main() -> int:
    original = SOURCE.read_text()
    all_tests = [t for _, _, tests in MUTANTS for t in tests]
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        code, summary = run_tests(compile_variant(original, work, "original"), all_tests)
        print(f"{'unpatched contract':38} -> {summary}")
        ok &= code == 0
        for i, (check, condition, tests) in enumerate(MUTANTS):
            pattern = re.compile(r"if \(" + re.escape(condition) + r"\) revert")
            patched, count = pattern.subn("if (false) revert", original)
            if count != 1:
                print(f"{check:38} -> condition not found exactly once ({count})")
                ok = False
                continue
            code, summary = run_tests(compile_variant(patched, work, f"mutant{i}"), tests)
            caught = code == 1 and "passed" not in summary  # every selected test failed
            ok &= caught
            print(f"{'without: ' + check:38} -> {summary} ({'caught' if caught else 'NOT CAUGHT'})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
