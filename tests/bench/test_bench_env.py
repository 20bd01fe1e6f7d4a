"""bench --env reports the vector env's rates beside the engine's (measured, never asserted)."""
import json

import pytest

from infomarket.cli import main


def test_bench_env_json_reports_the_vector_rates_and_their_ratio_to_the_engines(capsys):
    pytest.importorskip("gymnasium")
    assert main(["bench", "--env", "--steps", "60", "--repeats", "1", "--batch", "3", "--interval", "10",
                 "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert (r["batch"], r["interval"], r["steps"], r["agents"], r["robots"]) == (3, 10, 60, 3, 25)
    assert r["vector_env_steps_per_second"] == pytest.approx(3 * 60 / r["vector_seconds_per_episode"])
    assert r["agent_steps_per_second"] == pytest.approx(r["vector_env_steps_per_second"] * 3 / 10)
    assert r["engine_env_steps_per_second"] == pytest.approx(60 / r["engine_seconds_per_run"])
    assert r["ratio_to_engine"] == pytest.approx(r["vector_env_steps_per_second"] / r["engine_env_steps_per_second"])
    assert r["goal"] == 0.9


def test_bench_env_text_names_both_rates(capsys):
    pytest.importorskip("gymnasium")
    assert main(["bench", "--env", "--steps", "40", "--repeats", "1", "--batch", "2"]) == 0
    out = capsys.readouterr().out
    assert "agent-steps/s" in out and "engine" in out and "of the engine's env-steps/s" in out


def test_bench_env_is_exclusive_with_the_other_modes(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--env", "--scaling"])
    assert exc.value.code == 2


def test_batch_and_interval_without_env_are_refused(capsys):
    assert main(["bench", "--batch", "8", "--steps", "10"]) == 2
    assert "--batch and --interval go with --env" in capsys.readouterr().err
