"""Commands and extension paths without a test of their own elsewhere: ``infomarket demo``,
``reproduce --scale``, rules from the ``infomarket.plugins`` entry point, the plugin import fallback to
the current folder, and a new compiled kernel when a rule's source changes."""
from __future__ import annotations

import os
import sys
import textwrap

import pytest

import infomarket as im
from infomarket import plugins
from infomarket.cli import main
from infomarket.engine import specialise


def test_demo_prints_the_four_panels(capsys):
    assert main(["demo", "--runs", "1", "--workers", "1"]) == 0
    out = capsys.readouterr().out
    rows = {line.split("│")[1].strip(): [c.strip() for c in line.split("│")[1:-1]]
            for line in out.splitlines() if line.count("│") >= 6}
    assert {"2A", "2B", "2C", "2D"} <= set(rows)
    assert rows["2A"][1] == "25 naive" and rows["2A"][3] == "-"  # no Byzantine robot in 2A
    for panel in ("2A", "2B", "2C", "2D"):
        assert float(rows[panel][2]) >= 0  # a median number of items
    assert float(rows["2B"][3]) >= 0
    assert "4 runs" in out and "env-steps" in out


def test_reproduce_scale_takes_that_fraction_of_every_conditions_runs(tmp_path, monkeypatch):
    """Paper: 128 runs per panel of Figs. 2-4, 32 for Figs. 5-6 and for each of Fig. 7's 40 conditions
    (2 656 in all); at scale 1/8: 16, 4 and 4, so 10 x 16 + 3 x 4 + 40 x 4 = 332."""
    from infomarket.runner import sweep

    seen = []

    def record(conds, store, **kw):
        seen.extend(conds)
        return sweep.SweepReport(len(conds), 0, 0, 0, 1.0)

    monkeypatch.setattr(sweep, "run_sweep", record)
    assert main(["reproduce", "paper", "--out", str(tmp_path / "p"), "--scale", "0.125", "--quiet",
                 "--workers", "1"]) == 0
    runs = {}
    for c in seen:
        runs.setdefault(c.experiment, set()).add(c.runs)
    assert runs == {**{f"fig{n}{p}": {16} for n in (2, 3, 4) for p in ("ABCD" if n == 2 else "ABC")},
                    "fig5": {4}, "fig6A": {4}, "fig6B": {4}, "fig7": {4}}
    assert sum(c.runs for c in seen) == 332
    seen.clear()
    assert main(["reproduce", "paper", "--out", str(tmp_path / "q"), "--scale", "0.001", "--quiet"]) == 0
    assert {c.runs for c in seen} == {2}  # never fewer than two runs per condition


def test_rules_from_the_infomarket_plugins_entry_point_are_registered(tmp_path, procs):
    """An installed distribution that declares ``[infomarket.plugins]`` gets its module imported."""
    (tmp_path / "ep_rules_demo.py").write_text(textwrap.dedent("""
        import infomarket as im

        def silent(w, me, site):
            return False, 0.0, 0.0, 0

        im.register_behaviour("ep_silent", buy="naive", sell=silent, honest=False)
    """))
    dist = tmp_path / "ep_rules_demo-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: ep-rules-demo\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[infomarket.plugins]\nrules = ep_rules_demo\n")
    code = "import infomarket as im; print(sorted(im.registry.behaviours()))"
    env = {"PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    out = procs.run([sys.executable, "-c", code], env=env, check=True).stdout
    assert "ep_silent" in out
    bare = procs.run([sys.executable, "-c", code], check=True).stdout
    assert "ep_silent" not in bare  # it came from the entry point, not from anywhere else


def test_a_plugin_module_is_found_in_the_current_folder(tmp_path, monkeypatch):
    (tmp_path / "cwd_rules_demo.py").write_text(textwrap.dedent("""
        import infomarket as im

        def silent(w, me, site):
            return False, 0.0, 0.0, 0

        im.register_behaviour("cwd_silent", buy="naive", sell=silent, honest=False, replace=True)
    """))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", ".", str(tmp_path))])
    monkeypatch.delitem(sys.modules, "cwd_rules_demo", raising=False)
    plugins.load("cwd_rules_demo")
    assert "cwd_silent" in im.registry.behaviours()
    with pytest.raises(ModuleNotFoundError):
        plugins.load("no_such_rules_module_anywhere")
    assert plugins.resolve("r.py", tmp_path / "sub") == str((tmp_path / "sub" / "r.py").resolve())
    assert plugins.resolve("pkg.rules", tmp_path) == "pkg.rules"


RULE = """
import infomarket as im

def sell(w, me, site):
    return {answer}

im.register_behaviour("tmp_edited_rule", buy="naive", sell=sell, honest=False, replace=True)
"""


def test_an_edited_rule_gets_a_new_kernel(tmp_path, monkeypatch):
    """The kernel's name hashes every rule's source, so editing a rule compiles a new kernel, and an
    unchanged rule reuses the one on disk (same file name, so numba's own cache applies)."""
    import importlib.util

    monkeypatch.setenv("INFOMARKET_CACHE_DIR", str(tmp_path / "cache"))
    rules = tmp_path / "edited_rule.py"

    def kernel_for(answer: str):
        rules.write_text(RULE.format(answer=answer))
        spec = importlib.util.spec_from_file_location("tmp_edited_rule_module", rules)
        spec.loader.exec_module(importlib.util.module_from_spec(spec))
        return specialise.kernel_module(("naive", "tmp_edited_rule"), "delayed")

    first = kernel_for("False, 0.0, 0.0, 0")
    assert kernel_for("False, 0.0, 0.0, 0").__file__ == first.__file__
    edited = kernel_for("w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], 0")
    assert edited.__file__ != first.__file__
    assert len(list((tmp_path / "cache" / "kernels").glob("kernel_*.py"))) == 2


def test_sweep_future_plans_the_declared_grid_and_scales(tmp_path, monkeypatch, capsys):
    """The open-questions sweep (issue 10): per attack 6 angles x {1, 3} Byzantines x 4 defences = 48
    conditions, 3 attacks, plus 4 honest baselines = 148 conditions of 32 runs (4 736); --scale 1/16
    gives 2 runs each.  Bad input is refused with exit 2 and nothing written."""
    from infomarket.runner import sweep

    seen = []

    def record(conds, store, **kw):
        seen.extend(conds)
        return sweep.SweepReport(len(conds), 0, 0, 0, 1.0)

    monkeypatch.setattr(sweep, "run_sweep", record)
    assert main(["sweep", "future", "--out", str(tmp_path / "f"), "--quiet", "--workers", "1"]) == 0
    per = {}
    for c in seen:
        per.setdefault(c.experiment, []).append(c)
    assert {k: len(v) for k, v in per.items()} == {"future_honest": 4, "future_liar": 48, "future_farmer": 48,
                                                   "future_surfer": 48}
    assert sum(c.runs for c in seen) == 4736 and {c.config.steps for c in seen} == {30000}
    liar = {(c.keys["rotation_angle"], c.keys["byzantines"], c.keys["defence"]) for c in per["future_liar"]}
    assert {a for a, _, _ in liar} == {5.0, 10.0, 20.0, 25.0, 40.0, 90.0} and {b for _, b, _ in liar} == {1, 3}
    honest = {c.keys["defence"]: c.config for c in per["future_honest"]}
    assert honest["both"].swarm.groups[0].behaviour == "reputation_sceptic"
    assert honest["both"].payment.scheme == "adaptive_outlier" and honest["both"].payment.stake == 0.04
    surfer = {c.keys["defence"]: c.config.swarm.groups[1].params["adaptive"] for c in per["future_surfer"]}
    assert surfer == {"paper": 0.0, "reputation_sceptic": 0.0, "adaptive_theta": 1.0, "both": 1.0}
    seen.clear()
    assert main(["sweep", "future", "--out", str(tmp_path / "g"), "--scale", "0.0625", "--quiet"]) == 0
    assert {c.runs for c in seen} == {2} and len(seen) == 148
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(["sweep", "future", "--out", str(tmp_path / "h"), "--scale", "0"])
    assert exc.value.code == 2
    assert "--scale: must be in (0, 1]" in capsys.readouterr().err and not (tmp_path / "h").exists()
