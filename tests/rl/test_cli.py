"""infomarket rl-train: a tiny training from the command line, and bad input refused with exit 2."""
import json

import pytest

from infomarket.cli import main

pytest.importorskip("gymnasium")

TINY = ["--steps", "300", "--transitory", "100", "--iterations", "1", "--pairs", "1", "--eval-runs", "2"]


def test_rl_train_writes_the_policy_and_the_comparison(tmp_path, capsys):
    out = tmp_path / "r.json"
    assert main(["rl-train", *TINY, "--seed", "2", "--out", str(out), "--json", "--quiet"]) == 0
    r = json.loads(out.read_text())
    assert json.loads(capsys.readouterr().out)["theta"] == r["theta"]
    assert len(r["theta"]) == 20 and len(r["theta"][0]) == 2  # 19 observations + bias, 2 actions
    assert len(r["liar_items"]) == len(r["learned_items"]) == 2 and len(r["fitness"]) == 1
    assert r["beats_constant_liar"] == "inconclusive"  # 2 runs cannot decide (smallest p = 0.25)
    assert r["settings"]["pairs"] == 1


@pytest.mark.parametrize("args, message", [
    (["fig2A"], "no robot runs `attacker`"),
    (["--defence", "nonsense"], "matches 0 conditions"),
    (["--transitory", "400"], "--transitory 400: must be below --steps 300"),
])
def test_rl_train_refuses_bad_input_with_exit_2_and_writes_nothing(args, message, tmp_path, capsys):
    out = tmp_path / "r.json"
    first = [a for a in args if not a.startswith("-")][:1] if args[0] == "fig2A" else []
    rest = args[1:] if first else args
    assert main(["rl-train", *first, *TINY, *rest, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
