"""Failure isolation: a run that raises (here a user's plugin with a bug, in one condition of a grid) is
committed as failed with its error text; every other run completes; --retry-failed reruns only those."""

import pytest

from infomarket.cli import main
from infomarket.store import Store

PLUGIN = '''
import infomarket as im
from infomarket.behaviours.api import own_entry


@im.behaviour("boom_seller", buy="naive", honest=True, description="a seller whose rule raises when boom > 0")
def boom_sell(w, me, site, rng, boom=0.0):  # takes rng: asked every step, with a neighbour or not
    if boom > 0.0:
        raise ValueError("boom: a bug in a plugin")
    return own_entry(w, me, site)
'''

EXPERIMENT = '''
name = "buggy"
steps = 200
runs = 2
seed = 1
plugins = ["boom.py"]

[swarm]
robots = 6

[[swarm.groups]]
behaviour = "boom_seller"
count = 6

[sweep.grid]
"swarm.groups[0].params.boom" = [0.0, 1.0]
"payment.information_share" = [0.25, 0.5]
'''


@pytest.fixture
def buggy(tmp_path):
    (tmp_path / "boom.py").write_text(PLUGIN)
    p = tmp_path / "buggy.toml"
    p.write_text(EXPERIMENT)
    return p


def test_a_failing_condition_does_not_stop_the_others(buggy, tmp_path, capsys):
    out = tmp_path / "s"
    code = main(["sweep", str(buggy), "--out", str(out), "--workers", "1", "--quiet"])
    assert code == 2  # a user's rule raised: the user's to fix (issue 21), named with its file, line and step
    err = capsys.readouterr().err
    assert "4 of 8 runs failed" in err and "boom: a bug in a plugin" in err
    assert "behaviour 'boom_seller': its sell rule boom_sell raised ValueError" in err
    assert "at step 1" in err and f"{tmp_path / 'boom.py'}:9" in err and "Traceback" not in err
    assert f"infomarket store failed {out}" in err
    runs = Store(out).runs()
    assert len(runs) == 8
    ok = runs[runs.status == "ok"]
    assert sorted(ok.boom.unique()) == [0.0] and len(ok) == 4  # every run of the healthy conditions
    failed = Store(out).failed()
    assert len(failed) == 4 and set(failed.boom) == {1.0}
    assert all("boom_sell raised ValueError (boom: a bug in a plugin) at step 1" in e for e in failed.error)
    assert len(Store(out).robots()) == 4 * 6  # failed runs have no robot rows
    assert main(["store", "failed", str(out)]) == 0
    assert capsys.readouterr().out.count("ValueError (boom") == 4

    # a plain resume does not rerun them; --retry-failed reruns exactly those (and they fail again)
    assert main(["sweep", str(buggy), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert main(["sweep", str(buggy), "--out", str(out), "--workers", "1", "--retry-failed"]) == 2
    captured = capsys.readouterr()
    assert "4 runs done, 4 already in the store" in captured.out
    runs = Store(out).runs()
    assert len(runs) == 8 and not runs.duplicated(["condition", "run"]).any()
