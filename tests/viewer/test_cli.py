"""``infomarket view`` and ``infomarket replay`` through the main command line."""
from __future__ import annotations

import pytest

from infomarket.cli import main


def test_replay_writes_a_page_and_a_movie(tmp_path, capsys):
    out, gif = tmp_path / "run.html", tmp_path / "run.gif"
    assert main(["replay", "fig2B", "--steps", "60", "--every", "20", "--seed", "4",
                 "--out", str(out), "--movie", str(gif)]) == 0
    assert out.stat().st_size > 10_000 and gif.stat().st_size > 10_000
    err = capsys.readouterr().err
    assert "recorded 60 steps of fig2B (seed 4): 4 frames" in err and f"wrote {out}" in err


@pytest.mark.parametrize("argv, needle", [
    (["replay", "fig2B"], "say what to write"),
    (["replay", "no-such-experiment", "--out", "{tmp}/x.html"], "no-such-experiment"),
    (["replay", "fig2B", "--movie", "{tmp}/x.avi"], ".mp4 or .gif"),
    (["replay", "fig2B", "--out", "{tmp}/missing/x.html"], "existing folder"),
    (["view", "no-such-experiment"], "no-such-experiment"),
])
def test_bad_input_is_one_clear_message_and_exit_2(tmp_path, capsys, argv, needle):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("infomarket: error:") and needle in err and "Traceback" not in err
    assert not list(tmp_path.iterdir()), "nothing is written on bad input"


@pytest.mark.parametrize("argv", [["view", "fig2B", "--port", "70000"], ["view", "fig2B", "--seed", "-3"],
                                  ["replay", "fig2B", "--every", "0", "--out", "x.html"]])
def test_bad_options_are_usage_errors(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert "error:" in capsys.readouterr().err
