"""Malformed experiment files: one clear message naming the key, exit code 2, no traceback, nothing written."""
import sys
from pathlib import Path

import pytest

from infomarket.cli import main
from infomarket.config import load_experiment, validate
from infomarket.errors import ConfigError

BAD = Path(__file__).parents[1] / "fixtures" / "bad_experiments"
#: what the message must name for each fixture (the key, and what is allowed)
EXPECT = {
    "01_unknown_key": ["stepz", "unknown key", "allowed keys", "steps"],
    "02_wrong_type": ["steps", "integer"],
    "03_negative_speed": ["robot.speed", "greater than 0"],
    "04_more_robots_than_swarm": ["count = 30", "robots = 25"],
    "05_site_outside_arena": ["food", "outside the arena"],
    "06_threshold_not_positive": ["threshold", "> 0"],
    "07_unknown_behaviour": ["telepathic", "allowed", "sceptical"],
    "08_toml_syntax": ["not valid TOML", "line"],
    "09_share_above_one": ["payment.information_share", "less than or equal to 1"],
    "10_transitory_not_below_steps": ["transitory = 1000", "smaller than steps"],
    "11_legacy_unknown_class": ["behaviors[0].class", "TelepathicBehavior", "NaiveBehavior"],
    "12_unknown_nested_key": ["robot.warp", "unknown key", "speed"],
}


def test_every_fixture_has_expectations():
    assert sorted(p.stem for p in BAD.iterdir()) == sorted(EXPECT)
    assert len(EXPECT) >= 10


@pytest.mark.parametrize("name", sorted(EXPECT))
def test_bad_file_is_rejected_before_anything_is_written(name, tmp_path, capsys):
    path = next(BAD.glob(name + ".*"))
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "--runs", "1", "--steps", "10"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("infomarket: error: ") and "Traceback" not in err
    for fragment in EXPECT[name]:
        assert fragment in err, f"{fragment!r} missing from: {err}"
    assert not out.exists()


def test_real_process_exit_code_and_no_traceback(tmp_path, procs):
    proc = procs.run([sys.executable, "-m", "infomarket.cli", "run", str(BAD / "03_negative_speed.toml"),
                      "--out", str(tmp_path / "o")])
    assert proc.returncode == 2
    assert "robot.speed" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "o").exists()


def test_unknown_experiment_name_lists_shipped(capsys):
    assert main(["check", "fig99"]) == 2
    err = capsys.readouterr().err
    assert "fig99" in err and "fig2A" in err


def test_bad_command_line_value_exits_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "fig2A", "--runs", "0"])
    assert exc.value.code == 2
    assert "--runs" in capsys.readouterr().err


def test_unwritable_output_folder(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["run", "fig2A", "--out", str(blocker), "--steps", "10", "--runs", "1"]) == 2
    assert "not a directory" in capsys.readouterr().err


def test_defaults_are_the_papers():
    cfg = validate({"swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 25}]}})
    assert (cfg.arena.width, cfg.arena.height, cfg.robot.radius, cfg.robot.speed) == (1200, 600, 8, 2.5)
    assert (cfg.robot.communication_range, cfg.random_walk.rho, cfg.random_walk.alpha) == (50, 0.9, 1.4)
    assert (cfg.payment.initial_wealth, cfg.payment.reward, cfg.payment.information_share) == (1, 1, 0.5)


def test_shipped_experiments_load():
    for name in ("fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig3B", "fig3C", "fig4A", "fig4B", "fig4C",
                 "fig5", "fig6A", "fig6B"):
        cfg = load_experiment(name)
        assert cfg.swarm.robots == 25 and cfg.name == name


def test_zero_count_groups_are_allowed_and_ignored():
    cfg = validate({"swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2},
                                                      {"behaviour": "saboteur", "count": 0}]}})
    assert sum(g.count for g in cfg.swarm.groups) == 2


def test_config_errors_are_value_errors():
    with pytest.raises(ValueError):
        validate({"swarm": {"robots": 1, "groups": []}})
    assert issubclass(ConfigError, ValueError)
