"""The suite's profiling plugin (``tests/kernel_profile.py``) still runs against the package: it wraps
functions of the package by name, so a rename there breaks it at start-up, not in any test."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from tests import kernel_profile

ROOT = Path(__file__).resolve().parents[1]


def test_the_profile_plugin_records_every_test_and_its_summary_reads_them(procs, tmp_path):
    (tmp_path / "test_two.py").write_text("def test_one():\n    pass\n\n\ndef test_two():\n    pass\n")
    out = tmp_path / "prof.jsonl"
    proc = procs.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "tests.kernel_profile",
                      str(tmp_path / "test_two.py")],
                     cwd=ROOT, env={"KERNEL_PROFILE": str(out), "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stdout + proc.stderr
    records = [json.loads(line) for line in out.read_text().splitlines()]
    assert sorted(r["test"].rsplit("::", 1)[1] for r in records) == ["test_one", "test_two"]
    assert kernel_profile.summary(str(out)).startswith("2 tests, ")
