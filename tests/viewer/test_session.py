"""A page's session: command validation, stepping, restarting, selection."""
from __future__ import annotations

import json

import pytest

from infomarket.seeds import MAX_SEED
from infomarket.viewer.frames import decode
from infomarket.viewer.session import MAX_SPEED, Command, CommandError, Session, parse_command


@pytest.mark.parametrize("msg, want", [
    ({"cmd": "play"}, Command("play")),
    ({"cmd": "pause"}, Command("pause")),
    ({"cmd": "ack"}, Command("ack")),
    ({"cmd": "step"}, Command("step", 1)),
    ({"cmd": "step", "n": 40}, Command("step", 40)),
    ({"cmd": "speed", "value": MAX_SPEED}, Command("speed", MAX_SPEED)),
    ({"cmd": "restart"}, Command("restart", None)),
    ({"cmd": "restart", "seed": 9}, Command("restart", 9)),
    ({"cmd": "restart", "seed": MAX_SEED}, Command("restart", MAX_SEED)),
    ({"cmd": "restart", "seed": str(MAX_SEED)}, Command("restart", MAX_SEED)),  # the page sends text
    ({"cmd": "select", "robot": 0}, Command("select", 0)),
    ({"cmd": "select", "robot": None}, Command("select", None)),
])
def test_valid_commands(msg, want):
    assert parse_command(json.dumps(msg), robots=25) == want


@pytest.mark.parametrize("text, why", [
    ("{", "not JSON: '{'"),
    ("3", "expected an object"),
    ('{"cmd": 1}', "expected an object"),
    ('{"cmd": "jump"}', "unknown command 'jump'"),
    ('{"cmd": "step", "n": 0}', "step: n must be an integer in [1, "),
    ('{"cmd": "step", "n": 1.5}', "got 1.5"),
    (f'{{"cmd": "speed", "value": {MAX_SPEED + 1}}}',
     f"speed: value must be an integer in [1, {MAX_SPEED}], got {MAX_SPEED + 1}"),
    ('{"cmd": "speed"}', "speed: value must be an integer in [1, "),
    ('{"cmd": "select", "robot": -1}', "select: robot must be an integer in [0, 24], got -1"),
    ('{"cmd": "select", "robot": "3"}', "got '3'"),
    ('{"cmd": "restart", "seed": false}', "restart: seed must be an integer"),
    (f'{{"cmd": "restart", "seed": {MAX_SEED + 1}}}', f"restart: seed must be an integer in [0, {MAX_SEED}]"),
    ('{"cmd": "restart", "seed": "-3"}', "restart: seed must be an integer in [0, "),
    ('{"cmd": "restart", "seed": "7a"}', "got '7a'"),
])
def test_invalid_commands_say_why(text, why):
    with pytest.raises(CommandError) as err:
        parse_command(text, robots=25)
    assert why in str(err.value)


def test_session_steps_restarts_and_reports(fig2b):
    s = Session(fig2b, seed=4)
    assert s.status() == {"type": "status", "playing": False, "speed": 10, "step": 0, "seed": 4,
                          "selected": None}
    frame, detail = s.advance(12)
    assert decode(frame, s.robots).step == 12 and detail is None
    s.selected = 3
    _, detail = s.advance(1)
    assert detail["id"] == 3 and detail["step"] == 13
    s.restart()
    assert s.sim.clock == 0 and s.seed != 4 and s.scene()["seed"] == s.seed
    s.restart(4)
    assert s.seed == 4


def test_a_random_seed_spans_the_whole_seed_range(fig2b, monkeypatch):
    """The viewer draws its seeds from [0, MAX_SEED] (infomarket.seeds), the range of every other seed."""
    import infomarket.viewer.session as session
    drawn = []
    monkeypatch.setattr(session.secrets, "randbelow", lambda n: drawn.append(n) or n - 1)
    s = Session(fig2b)
    assert drawn == [MAX_SEED + 1] and s.seed == MAX_SEED and s.scene()["seed_text"] == str(MAX_SEED)
