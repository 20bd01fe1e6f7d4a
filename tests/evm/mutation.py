"""Mutation check for the attack tests: remove each of the contract's checks in turn and show that the
test guarding it fails.

Each mutant is a copy of contracts/ (the contract and the modules it imports) with one check removed
from the one file that holds it: an ``if (<check>) revert ...`` turned into ``if (false) revert ...``,
or one rule replaced by a wrong one (``REWRITES``: the similarity computed from something else, expiry
ignored); a text found in no file or more than once across the files is reported, not guessed. Each is
compiled by the pinned solc-js into a temporary artifact, against which the tests guarding it run (through
``INFOMARKET_CHAIN_ARTIFACT``, see conftest.py; on revm only). It needs Node and takes a few minutes,
so it is a script, not part of the test suite:

    .venv/bin/python tests/evm/mutation.py [WORD ...]

With words, only the mutants whose label contains one of them run (the unpatched copy always does).
Exit status 0 when every mutant is caught (a test guarding it fails) and the unpatched copy passes them.
"""
from __future__ import annotations

import re
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # a script: the checkout's tests package, for its one way to start a process
from tests.procs import Procs  # noqa: E402 - after the checkout is on the path

CONTRACTS = ROOT / "contracts"
COMPILER = ROOT / "tools" / "solc" / "compile.js"
TESTS = ROOT / "tests" / "evm"

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
    ("caller holds the role", "!_roles[role][msg.sender]",
     ["test_only_a_depositor", "test_only_registrars_approve", "test_the_admin_rotates"]),
    ("signature s is low", "uint256(s) > _HALF_ORDER",
     ["test_a_malleated_high_s_signature", "test_a_deposit_needs_the_robots"]),
    ("seller vector in range",
     "dx >= _MAX_COMPONENT || dx <= -_MAX_COMPONENT || dy >= _MAX_COMPONENT || dy <= -_MAX_COMPONENT",
     ["test_malformed_site_and_vector_out_of_range"]),
    ("records per seller bounded", "n >= _maxRecordsPerSeller",
     ["test_one_seller_cannot_fill"]),
    ("further records leave room for sellers not yet heard", "2 * (repeats + 1) + firsts > _maxRecordsPerTrip",
     ["test_six_colluders"]),
    ("max block not too far ahead", "offer.maxBlock > block.number + _maxValidity",
     ["test_a_light_contract_cannot_stay_open"]),
    ("previous settlement finished", "s.end != 0",
     ["test_a_pending_settlement_blocks"]),
    ("round trip below its live-record bound", "index - round.start >= _maxRecordsPerTrip",
     ["test_a_buyer_that_signs_many_offers"]),
    ("the signed round trip is the open one", "lc.trip != round.trip",
     ["test_a_reveal_after_the_buyers_deposit"]),
    ("seller registered", "!_registered[seller]", ["test_an_unregistered_account"]),
    ("buyer registered", "!_registered[buyer]", ["test_an_unregistered_account"]),
    ("depositing robot registered", "!_registered[robot]", ["test_an_unregistered_account"]),
    ("wealth granted once", "_registered[robot] || _exits[robot].state != 0",
     ["test_the_market_grants_wealth_once", "test_a_bond_comes_back", "test_the_registrars_revoke"]),
    ("grant covers the bond", "amount < _registrationBond", ["test_one_registrar_cannot"]),
    ("bond within the largest grant", "registrationBond_ > maxGrant_", ["test_the_trip_bound_and_the_batch_bound"]),
    ("bond delay between 1 and 2^40", "bondDelay_ == 0 || bondDelay_ > _MAX_DELAY",
     ["test_the_trip_bound_and_the_batch_bound"]),
    ("only a registered robot exits", "!_registered[msg.sender]", ["test_a_bond_comes_back"]),
    ("a bond withdrawn once, after an exit", "e.state != _EXITING",
     ["test_a_bond_comes_back", "test_the_registrars_revoke"]),
    ("a bond withdrawn after its delay", "block.number < e.at", ["test_a_bond_comes_back"]),
    ("only a bonded robot is revoked", "!_registered[robot] && e.state != _EXITING", ["test_the_registrars_revoke"]),
    ("grant within its cap", "amount > _maxGrant", ["test_the_market_grants_wealth_once"]),
    ("trip bound at most 512", "maxRecordsPerTrip_ == 0 || maxRecordsPerTrip_ > _MAX_TRIP_RECORDS",
     ["test_the_trip_bound_and_the_batch_bound"]),
    ("batch at most 48", "settleBatch_ == 0 || settleBatch_ > _MAX_SETTLE_BATCH",
     ["test_the_trip_bound_and_the_batch_bound"]),
    ("stake expiry never off", "stakeExpiry_ == 0", ["test_the_trip_bound_and_the_batch_bound"]),
    ("settlement deadline never off", "settlementDeadline_ == 0", ["test_the_trip_bound_and_the_batch_bound"]),
    ("registrar threshold within the registrars",
     "registrarThreshold_ == 0 || registrarThreshold_ > registrars_.length",
     ["test_the_trip_bound_and_the_batch_bound"]),
    ("registrar quota never 0", "registrarQuota_ == 0", ["test_the_trip_bound_and_the_batch_bound"]),
    ("registrar period never 0", "registrarPeriod_ == 0", ["test_the_trip_bound_and_the_batch_bound"]),
    ("largest bounty within the share",
     "settleBounty_ * _MAX_SETTLEMENT_UNITS > (reward_ * informationShare_) / _WAD",
     ["test_the_trip_bound_and_the_batch_bound"]),
    ("not paused", "_paused", ["test_a_pause_stops"]),
    ("a standing approval is not given twice", "_stands(msg.sender, at)",
     ["test_one_registrar_cannot", "test_the_registrars_revoke"]),
    ("a registrar within its quota",
     "used >= _registrarQuota && uint256(_quotaBlocks[msg.sender][slot]) + _registrarPeriod > block.number",
     ["test_only_registrars_approve_and_each_within", "test_the_quota_holds_in_every_window"]),
    ("only a standing approval is cancelled", "!_stands(msg.sender, _approvedAt[request][msg.sender])",
     ["test_an_approval_lapses_after_its_window_and_can_be_cancelled"]),
    ("deposit signed by the robot", "signer == address(0) || signer != robot", ["test_a_deposit_needs_the_robots"]),
    ("deposit acknowledged by a nest", "signer == address(0) || !_roles[NEST_ROLE][signer]",
     ["test_a_deposit_needs_the_robots"]),
    ("capped: a cap under OutlierCapped only", "scheme_ == Scheme.OutlierCapped ? cap_ == 0 : cap_ != 0",
     ["test_the_cap_is_a_constructor_parameter"]),
    ("capped: reward below 2^96", "reward_ >= _MAX_CAPPED_AMOUNT", ["test_the_cap_is_a_constructor_parameter"]),
    ("capped: stake below 2^96", "stake_ >= _MAX_CAPPED_AMOUNT", ["test_the_cap_is_a_constructor_parameter"]),
    ("a revocation reversed only within its window", "e.state != _REVOKED || block.number >= e.at",
     ["test_a_revocation_stands_after"]),
]

#: (the rule broken, text replaced, its wrong replacement, tests that must then fail)
REWRITES = [
    ("weights from the committed vector",
     "(int64 dx, int64 dy) = _sellerVector(info.x, info.y, lc.sellerX, lc.sellerY);",
     "(int64 dx, int64 dy) = _sellerVector(info.x, info.y, 0, 0);",
     ["test_a_saboteurs_rotated_vector", "test_a_settlement_can_be_recomputed"]),
    ("similarity strictly within theta", "if (c >= 0) return d > 0 && lhs > rhs;",
     "if (c >= 0) return d > 0 && lhs >= rhs;",
     ["test_similarity_is_an_exact_integer_test"]),
    ("zero vector has direction 0", "return x == 0 && y == 0 ? (int64(1), int64(0)) : (x, y);",
     "return (x, y);", ["test_similarity_is_an_exact_integer_test"]),
    ("a round trip expires stakeExpiry blocks after its first record",
     "return uint256(openedAt) + _stakeExpiry <= now_;", "return uint256(openedAt) + _stakeExpiry < now_;",
     ["test_a_robot_that_dies"]),
    ("settle capped at one batch", "return _settle(robot, maxRecords < _settleBatch ? maxRecords : _settleBatch);",
     "return _settle(robot, maxRecords);", ["test_no_call_does_more_than_one_batch"]),
    ("refundExpired capped at one batch",
     "_close(buyer, share, maxRecords < _settleBatch ? maxRecords : _settleBatch);",
     "_close(buyer, share, maxRecords);", ["test_no_call_does_more_than_one_batch"]),
    ("a late settlement weighs as a prompt one", "bool equal = _scheme == Scheme.Delayed;",
     "bool equal = _scheme == Scheme.Delayed || late;",
     ["test_a_liar_is_paid_by_weight", "test_a_deposit_not_weighed_by_its_deadline",
      "test_an_expired_round_trip_left_past_the_deadline"]),
    ("past the deadline anyone earns the bounty",
     "bool late = block.number >= uint256(s.closedAt) + _settlementDeadline;", "bool late = false;",
     ["test_a_liar_is_paid_by_weight", "test_a_deposit_not_weighed_by_its_deadline",
      "test_an_expired_round_trip_left_past_the_deadline"]),
    ("a seller counts once", "if (sites[j] != site || mark[rank[j]] == i + 1) continue;",
     "if (sites[j] != site || j == i) continue;",
     ["test_a_repeating_seller_gets_one_sellers_share", "test_a_copying_seller"]),
    ("a seller's weight split across its records", "w = (w * _DISTINCT_SCALE) / sales[2 * rank[i] + site];",
     "w = w * _DISTINCT_SCALE;", ["test_a_repeating_seller_gets_one_sellers_share", "test_a_copying_seller"]),
    ("a seller's records linked", "if (gap <= _MAX_TRIP_RECORDS) prevGap = uint16(gap);", "",
     ["test_a_repeating_seller_gets_one_sellers_share", "test_a_copying_seller"]),
    ("sale key includes the path hash",
     "bytes32 key = revealKey(offer.site, offer.age, offer.maxBlock, buyer, seller, offer.pathHash);",
     "bytes32 key = revealKey(offer.site, offer.age, offer.maxBlock, buyer, seller, bytes32(0));",
     ["test_a_second_different_sale"]),
    ("similar() range-checked", "(ax, ay) = _sellerVector(ax, ay, 0, 0);", "(ax, ay) = _nonZero(ax, ay);",
     ["test_similar_refuses_vectors_beyond"]),
    ("indices restart only under an empty round trip", "if (round.count == round.first) {",
     "if (true) {", ["test_a_refunded_record_under_a_pending_settlement"]),
    ("registration needs the threshold", "if (count < _registrarThreshold) return false;", "",
     ["test_one_registrar_cannot", "test_a_single_compromised_registrar"]),
    ("revocation needs the threshold", "revoked = count >= _registrarThreshold;", "revoked = true;",
     ["test_the_registrars_revoke"]),
    ("an exited or revoked robot never registers again", "_registered[robot] || _exits[robot].state != 0",
     "_registered[robot]", ["test_a_bond_comes_back", "test_the_registrars_revoke"]),
    ("registration locks the bond", "_balances[robot] += amount - _registrationBond;",
     "_balances[robot] += amount;", ["test_one_registrar_cannot"]),
    ("a clean exit returns the bond", "amount = _registrationBond;", "amount = 0;", ["test_a_bond_comes_back"]),
    ("a revoked bond is burned", "_totalSupply -= _registrationBond;", "", ["test_the_registrars_revoke"]),
    ("an expiry charges the buyer the share", "_balances[buyer] = balance - share;", "share = 0;",
     ["test_a_liar_is_no_better_off", "test_a_buyer_that_waits", "test_an_expired_round_trip_is_settled_alone"]),
    ("a short share is the buyer's balance", "if (share > balance) share = balance;", "",
     ["test_a_buyer_that_cannot_pay"]),
    ("a bounty paused in weighing never exceeds the escrow",
     "if (bounty > escrow) bounty = escrow; // an expired round trip's share may be short", "",
     ["test_a_buyer_that_cannot_pay"]),
    ("a bounty at the start of paying never exceeds the escrow",
     "if (bounty > escrow) bounty = escrow;\n            escrow -= bounty;", "escrow -= bounty;",
     ["test_a_buyer_that_cannot_pay"]),
    ("paying starts at the round trip's first record", "            next = first;\n", "",
     ["test_a_buyer_that_waits", "test_an_expired_round_trip_left_past_the_deadline"]),
    ("a revoked role is gone", "            _roles[role][account] = false;\n", "",
     ["test_the_admin_rotates"]),
    ("bounty for registered robots only", "_settleBounty != 0 && (_registered[msg.sender] || late) ? _settleBounty : 0",
     "_settleBounty", ["test_the_depositor_earns_no_bounty", "test_a_pending_settlement_blocks"]),
    ("bounty cut from each payment", "uint256 cut = rate < share ? rate : share;", "uint256 cut = 0;",
     ["test_a_robot_that_settles_earns_the_bounty"]),
    ("distinct weighing costs more units",
     "uint256 per = _scheme == Scheme.OutlierDistinct ? _DISTINCT_PAIRS_PER_UNIT : _PAIRS_PER_UNIT;",
     "uint256 per = _PAIRS_PER_UNIT;", ["test_a_distinct_seller_weighing_costs"]),
    ("capped: records past the cap are void", "if (p >= _cap) sites[k] = _VOID;", "if (p > _cap) sites[k] = _VOID;",
     ["test_a_capped_round_trip"]),
    ("capped: a void record weighs its stake", "weight = count == 0 ? _stake * sum :", "weight = count == 0 ? 0 :",
     ["test_a_capped_round_trip"]),
    ("capped: counted records over all weighing calls", "s.counted = uint64(counted);",
     "s.counted += uint64(counted);", ["test_a_capped_round_trip"]),
    ("further records counted per round trip", "_repeats[buyer] = ((trip + 1) << 64) | (repeats + 1);", "",
     ["test_six_colluders"]),
    ("an approval stands under its key's current grant only",
     "&& at >> 64 == _roleGrants[REGISTRAR_ROLE][registrar]", "", ["test_an_approval_by_a_key_whose_role_moved"]),
    ("an approval stands while its key holds the role", "_roles[REGISTRAR_ROLE][registrar]\n", "true\n",
     ["test_an_approval_by_a_key_whose_role_moved"]),
    ("an approval lapses after the period", "(at & type(uint64).max) + _registrarPeriod > block.number", "true",
     ["test_an_approval_lapses_after_its_window"]),
    ("a cancelled approval stops standing", "_approvedAt[request][msg.sender] = _CANCELLED;", "",
     ["test_an_approval_lapses_after_its_window"]),
    ("the quota's window slides", "_quotaBlocks[msg.sender][slot] = uint64(block.number);", "",
     ["test_the_quota_holds_in_every_window"]),
    ("revocations count against the quota",
     "uint256 count = _approve(keccak256(abi.encode(\"revoke\", robot, e.reinstated)), robot);",
     "uint256 count = _standing(keccak256(abi.encode(\"revoke\", robot, e.reinstated))) + 1;",
     ["test_revocations_count_against_the_quota"]),
    ("a gone buyer's round trip settled at once",
     "if (_registered[buyer] && !_expired(_records[buyer][first].openedAt, block.number)) return 0;",
     "if (!_expired(_records[buyer][first].openedAt, block.number)) return 0;",
     ["test_revocations_count_against_the_quota"]),
    ("reinstating takes more registrars than revoking", "reinstated = count > _registrarThreshold;",
     "reinstated = count >= _registrarThreshold;", ["test_a_revocation_by_two_compromised"]),
    ("approvals count anew after a reinstatement", "        e.reinstated += 1;\n", "",
     ["test_a_revocation_stands_after"]),
    ("a reinstated bond is minted back", "_totalSupply += _registrationBond;\n        emit RegistrationReinstated",
     "emit RegistrationReinstated", ["test_a_revocation_by_two_compromised"]),
    ("a robot revoked while exiting comes back exiting", "e.exiting = e.state == _EXITING;", "",
     ["test_a_revocation_stands_after"]),
    ("a pause that changes nothing emits nothing", "if (_paused == paused_) return;", "",
     ["test_a_pause_stops_registrations"]),
    ("batch bound 48", "uint256 internal constant _MAX_SETTLE_BATCH = 48;",
     "uint256 internal constant _MAX_SETTLE_BATCH = 64;", ["test_the_trip_bound_and_the_batch_bound"]),
]


def read_sources() -> dict[str, str]:
    """Every Solidity file of contracts/, by its path relative to that directory."""
    return {p.relative_to(CONTRACTS).as_posix(): p.read_text() for p in sorted(CONTRACTS.rglob("*.sol"))}


def compile_variant(sources: dict[str, str], workdir: Path, name: str) -> Path:
    """Compile a copy of contracts/ holding ``sources`` (under the same source names) into an artifact."""
    tree, out = workdir / name, workdir / f"{name}.json"
    for rel, text in sources.items():
        (tree / rel).parent.mkdir(parents=True, exist_ok=True)
        (tree / rel).write_text(text)
    with Procs() as procs:
        procs.run(["node", str(COMPILER), "--contracts", str(tree), "--out", str(out), "--allow-warnings"],
                  check=True)
    shutil.rmtree(tree)
    return out


def patch(sources: dict[str, str], edit) -> tuple[dict[str, str], int]:
    """Apply ``edit`` (text -> (new text, count)) to every file; (patched sources, total count)."""
    patched, total = {}, 0
    for rel, text in sources.items():
        patched[rel], count = edit(text)
        total += count
    return patched, total


def run_tests(artifact: Path, selected: list[str]) -> tuple[int, str]:
    """Run the chain tests whose names contain one of ``selected``; (exit code, summary line)."""
    env = dict(INFOMARKET_CHAIN_ARTIFACT=str(artifact), INFOMARKET_CHAIN_BACKENDS="revm")
    files = [str(TESTS / name) for name in ("test_attacks.py", "test_market.py", "attacks")]
    with Procs() as procs:
        done = procs.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *files,
                          "-k", " or ".join(selected)], env=env, cwd=ROOT)
    summary = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else done.stderr.strip()[-200:]
    return done.returncode, summary


def main(words: list[str] | None = None) -> int:
    original = read_sources()
    variants = []
    for check, condition, tests in MUTANTS:
        pattern = re.compile(r"if \(" + re.escape(condition) + r"\)(\s*\{?\s*)revert")
        edit = lambda text, pattern=pattern: pattern.subn(r"if (false)\1revert", text)  # noqa: E731 - binds the pattern
        variants.append(("without: " + check, *patch(original, edit), tests))
    for rule, old, new, tests in REWRITES:
        if tests:
            edit = lambda text, old=old, new=new: (text.replace(old, new), text.count(old))  # noqa: E731 - binds texts
            variants.append(("broken: " + rule, *patch(original, edit), tests))
    if words:
        variants = [v for v in variants if any(w in v[0] for w in words)]
    all_tests = [t for *_, tests in variants for t in tests]
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        code, summary = run_tests(compile_variant(original, work, "original"), all_tests)
        print(f"{'unpatched contract':38} -> {summary}")
        ok &= code == 0
        for i, (label, patched, count, tests) in enumerate(variants):
            if count != 1:
                print(f"{label:44} -> text not found exactly once ({count})")
                ok = False
                continue
            code, summary = run_tests(compile_variant(patched, work, f"mutant{i}"), tests)
            caught = code == 1  # a test guarding it failed (parametrised tests may fail in part)
            ok &= caught
            print(f"{label:44} -> {summary} ({'caught' if caught else 'NOT CAUGHT'})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
