"""The committed ABI + bytecode (src/infomarket/evm/artifacts) is what the pinned compiler makes of
the committed contract, so the Python side can run without Node and still never run stale code."""
from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from infomarket.evm.market import load_artifact

ROOT = Path(__file__).resolve().parents[2]
CONTRACTS = ROOT / "contracts"
TOOLS = ROOT / "tools" / "solc"


def test_artifact_records_the_sources_it_was_built_from():
    """Cheap staleness check that needs no compiler: every source file's hash is stored in the artifact,
    and every Solidity file under contracts/ is one the contract was built from (a module left out of
    the composition would otherwise go unnoticed)."""
    recorded = load_artifact()["sources"]
    present = {f"contracts/{p.relative_to(CONTRACTS).as_posix()}": hashlib.sha256(p.read_bytes()).hexdigest()
               for p in CONTRACTS.rglob("*.sol")}
    assert set(recorded) == set(present), (
        f"contracts/ and the artifact's sources differ ({sorted(set(recorded) ^ set(present))}): "
        "run `make contracts`")
    stale = sorted(name for name in present if recorded[name] != present[name])
    assert not stale, f"{stale} changed since the artifact was built: run `make contracts`"


def test_compiler_is_pinned_to_one_exact_version():
    wanted = json.loads((TOOLS / "package.json").read_text())["dependencies"]["solc"]
    assert wanted.replace(".", "").isdigit(), f"solc must be pinned exactly, not {wanted!r}"
    locked = json.loads((TOOLS / "package-lock.json").read_text())["packages"]["node_modules/solc"]["version"]
    assert locked == wanted
    assert load_artifact()["compiler"]["version"].startswith(f"{wanted}+commit.")


def test_recompiling_reproduces_the_committed_artifact(tmp_path, procs):
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("node and npm are not installed: cannot recompile the contract to check the artifact")
    if not (TOOLS / "node_modules" / "solc").is_dir():
        procs.run([npm, "ci", "--no-audit", "--no-fund"], cwd=TOOLS, check=True)
    fresh = tmp_path / "InformationMarket.json"
    procs.run([node, str(TOOLS / "compile.js"), "--out", str(fresh)], check=True)
    assert json.loads(fresh.read_text()) == load_artifact(), (
        "the committed artifact is stale: run `make contracts` and commit src/infomarket/evm/artifacts")
