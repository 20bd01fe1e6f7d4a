"""Issue 21: what broke when infomarket was tried as a new user would.  Each case gives one clear message and
exit code 2 (no traceback, nothing written outside the output folder), or the documented result."""
import json
import os

import pytest

from infomarket.cli import main
from infomarket.config import load_experiment, validate
from infomarket.errors import ConfigError

SMALL = """
name = {name}
steps = 50
runs = 1

[swarm]
robots = 2

[[swarm.groups]]
behaviour = "naive"
count = 2
"""


# ------------------------------------------------------------------ shipped names and same-named folders
def test_a_folder_named_like_a_shipped_experiment_does_not_hide_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fig2A").mkdir()  # e.g. what `infomarket sweep fig2A --out fig2A` wrote before
    assert main(["check", "fig2A"]) == 0
    assert capsys.readouterr().out.startswith("fig2A: valid. 25 naive")
    assert load_experiment("fig2A").swarm.groups[0].count == 25


@pytest.mark.parametrize("arg", ["./fig2A", "fig2A/"])
def test_an_argument_that_looks_like_a_path_names_the_folder_and_says_how_to_name_the_shipped_one(
        arg, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fig2A").mkdir()
    assert main(["check", arg]) == 2
    err = capsys.readouterr().err
    assert "is a directory, not an experiment file" in err and "`fig2A`" in err and "Traceback" not in err


def test_a_file_with_an_extension_is_read_even_when_its_stem_is_a_shipped_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fig2A.toml").write_text(SMALL.format(name='"mine"'))
    assert main(["check", "fig2A.toml"]) == 0
    assert capsys.readouterr().out.startswith("mine: valid. 2 naive")


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_a_file_nested_100000_levels_deep_is_one_clear_error(suffix, tmp_path, capsys):
    p = tmp_path / f"deep{suffix}"
    p.write_text("[" * 100_000 + "]" * 100_000 if suffix == ".json" else "a = " + "[" * 100_000 + "]" * 100_000)
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"infomarket: error: {p}") and "Traceback" not in err and len(err.splitlines()) == 1


# ------------------------------------------------------------------ names used as folders
@pytest.mark.parametrize("name", ["../../../../elsewhere/x", "/tmp/abs", "", "x" * 1_000_000, "a\x1b[31mred",
                                  "..", ".hidden", "a b", "a\\b", "x\n"])
def test_unsafe_names_are_refused_and_never_echoed_raw(name, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    p = tmp_path / "e.toml"
    p.write_text(SMALL.format(name=json.dumps(name)))
    before = sorted(os.listdir(tmp_path))
    assert main(["run", str(p), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"infomarket: error: {p}: invalid experiment\n  name: ") and "Traceback" not in err
    assert "\x1b" not in err and len(err) < 1000
    assert sorted(os.listdir(tmp_path)) == before  # nothing written, here or elsewhere
    assert not (tmp_path.parent / "elsewhere").exists()


def test_safe_names_and_the_default_from_the_file_name(tmp_path):
    for ok in ("fig2A", "two_food", "a.b-c+d=e,f", "_x", "9" * 100):
        assert validate({"name": ok, "swarm": {"robots": 1, "groups": [{"behaviour": "naive", "count": 1}]}}).name == ok
    p = tmp_path / "my first run (copy).toml"
    p.write_text(SMALL.replace("name = {name}\n", ""))
    assert load_experiment(p).name == "my_first_run__copy_"


def test_control_characters_in_a_path_are_not_echoed_raw(capsys):
    assert main(["check", "no\x1b[2Jsuch.toml"]) == 2
    err = capsys.readouterr().err
    assert "\x1b" not in err and "no\\x1b[2Jsuch.toml" in err


# ------------------------------------------------------------------ check says it ran plugin code
def test_check_says_that_it_imported_plugin_code(tmp_path, capsys):
    (tmp_path / "noted.py").write_text(
        "import infomarket as im\n\n\n"
        "def sell(w, me, site):\n"
        "    return w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], 0\n\n\n"
        "im.register_behaviour('tmp_noted', buy='naive', sell=sell, honest=False, replace=True)\n")
    exp = tmp_path / "noted.toml"
    exp.write_text(SMALL.format(name='"noted"').replace('behaviour = "naive"', 'behaviour = "tmp_noted"')
                   .replace("runs = 1", 'runs = 1\nplugins = ["noted.py"]'))
    assert main(["check", str(exp)]) == 0
    got = capsys.readouterr()
    assert "noted: valid. 2 tmp_noted" in got.out
    assert "imported (and so ran) the plugin code" in got.err and str(tmp_path / "noted.py") in got.err


# ------------------------------------------------------------------ the Python API's arguments
SWARM = {"steps": 40, "swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2}]}}


@pytest.mark.parametrize("kw,fragment", [({"steps": -1}, "steps must be a positive integer"),
                                         ({"steps": 1.5}, "steps must be a positive integer"),
                                         ({"history_every": -3}, "history_every must be an integer in [0, steps = 40]"),
                                         ({"history_every": 2.5}, "history_every must be an integer"),
                                         ({"history_every": 41},
                                          "history_every must be an integer in [0, steps = 40]")])
def test_simulate_refuses_impossible_lengths(kw, fragment):
    import infomarket as im

    cfg = validate(SWARM)
    with pytest.raises(ConfigError) as err:
        im.simulate(cfg, 1, **kw)
    assert fragment in str(err.value)


def test_simulate_takes_a_dict_and_validates_it_as_an_experiment():
    import infomarket as im

    res = im.simulate(SWARM, 1)
    assert res.steps == 40 and len(res.robots) == 2
    with pytest.raises(ConfigError, match=r"swarm.groups\[0\].count: Input should be greater than or equal to 0"):
        im.simulate({**SWARM, "swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": -2}]}})
    with pytest.raises(im.errors.InputTypeError, match="got int"):
        im.simulate(42)


# ------------------------------------------------------------------ defaults and impossible markets
def test_a_site_given_in_part_takes_the_defaults_of_the_rest():
    cfg = validate({**SWARM, "food": {"radius": 30.0}, "nest": {"x": 900.0}})
    assert (cfg.food.x, cfg.food.y, cfg.food.radius) == (200.0, 300.0, 30.0)  # README: every key has a default
    assert (cfg.nest.x, cfg.nest.y, cfg.nest.radius) == (900.0, 300.0, 50.0)
    with pytest.raises(ConfigError, match="food.y"):
        validate({**SWARM, "food": {"y": "high"}})


def test_a_stake_above_the_initial_wealth_is_refused(tmp_path, capsys):
    p = tmp_path / "stake.toml"
    p.write_text(SMALL.format(name='"stake"') + "\n[payment]\nstake = 2.0\n")
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert "payment.stake = 2.0 is more than payment.initial_wealth = 1.0" in err and "Traceback" not in err
    assert validate({**SWARM, "payment": {"stake": 1.0}}).payment.stake == 1.0  # equal: one purchase possible


def test_check_describes_a_grid_sweep_its_conditions_and_total_runs(capsys):
    assert main(["check", "fig7"]) == 0
    out = capsys.readouterr().out
    # fig7: rotation 0..90 by 10 (10 values) x 1 or 3 Byzantines x 2 markets = 40 conditions of 32 runs
    assert "32 runs per condition" in out
    assert "sweep: swarm.groups[1].params.rotation_angle (10 values) x byzantines (2 values) x market (2 values)" in out
    assert "sweep: 40 conditions x 32 runs = 1,280 runs" in out


# ------------------------------------------------------------------ rough edges of the command line
def test_a_shipped_name_in_the_wrong_case_suggests_the_right_one(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "fig2b", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "no experiment file 'fig2b'" in err and "did you mean fig2B?" in err
    assert os.listdir(tmp_path) == []


def test_a_slow_kernel_load_is_announced_on_stderr_unless_quiet(capsys, monkeypatch):
    import time

    from infomarket.engine.compiling import compile_notice

    monkeypatch.delenv("INFOMARKET_COMPILE_NOTICE", raising=False)
    err = ""
    with compile_notice(("naive", "saboteur", "naive"), "delayed", after=0.01):
        while not err:  # however long the notice's thread takes to be scheduled
            time.sleep(0.01)
            err += capsys.readouterr().err
    assert err == ("compiling the step kernel for naive+saboteur / delayed (once on this machine: "
                   "later runs load it from the cache)...\n")
    with compile_notice(("naive",), "delayed", after=3600.0):
        pass  # loaded from the cache before the notice was due: nothing to say
    monkeypatch.setenv("INFOMARKET_COMPILE_NOTICE", "0")  # what --quiet sets
    with compile_notice(("naive",), "delayed", after=0.01):
        time.sleep(0.2)
    time.sleep(0.6)
    assert capsys.readouterr().err == ""


def test_quiet_silences_the_compile_notice_for_the_command_only(monkeypatch):
    import infomarket.cli as cli

    seen = {}
    monkeypatch.delenv("INFOMARKET_COMPILE_NOTICE", raising=False)
    parser = cli.build_parser()
    args = parser.parse_args(["run", "fig2A", "--quiet"])
    args.func = lambda a: seen.setdefault("run", os.environ.get("INFOMARKET_COMPILE_NOTICE")) and 0
    monkeypatch.setattr(cli, "build_parser", lambda: type("P", (), {"parse_args": lambda self, argv: args})())
    assert cli.main(["run", "fig2A", "--quiet"]) == 0
    assert seen["run"] == "0" and "INFOMARKET_COMPILE_NOTICE" not in os.environ


def test_a_folder_named_like_a_shipped_suite_does_not_hide_it(tmp_path, monkeypatch):
    import infomarket.runner.cli as runner_cli

    monkeypatch.chdir(tmp_path)
    (tmp_path / "future").mkdir()  # what `infomarket sweep future --out future` wrote before
    got = {}
    monkeypatch.setattr(runner_cli, "_execute",
                        lambda exps, args, label: got.setdefault("names", [e.name for e in exps]) and 0)
    assert main(["sweep", "future", "--out", "future", "--quiet"]) == 0
    assert got["names"] == ["future_honest", "future_liar", "future_farmer", "future_surfer"]


def test_nesting_is_measured_outside_strings_and_comments():
    from infomarket.config.load import nesting_depth

    assert nesting_depth('a = [[1, 2], "[[[", \'[[\']  # [[[[', comments=True) == 2
    assert nesting_depth('{"a": ["\\"[", {"b": 1}]}', comments=False) == 3
