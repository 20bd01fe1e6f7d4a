"""The agent's questions to its robot's controller, without ROS 2: what is asked, which answer counts,
what a silent controller leads to."""
from __future__ import annotations

import json

import pytest

from infomarket.ros import wire
from infomarket.ros.decide import Decisions


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_a_question_is_asked_again_and_its_first_answer_counts():
    sent, clock = [], Clock()
    d = Decisions(sent.append, clock=clock)
    d.ask(4, "sell", {"buyer": 1})
    d.ask(4, "sell", {"buyer": 1})  # the task came again: the controller may have missed the question
    assert [json.loads(t) for t in sent] == [{"id": 4, "question": "sell", "buyer": 1}] * 2
    assert d.answer('{"id": 4, "question": "sell", "yes": false}') == (4, "sell", False)
    assert d.answer('{"id": 4, "question": "sell", "yes": true}') is None  # an answer to a repeat: ignored
    assert d.answer('{"id": 5, "question": "buy", "yes": true}') is None  # never asked
    clock.now = 1e9
    assert d.expired() == []  # no timeout: a question waits for its answer


@pytest.mark.parametrize("text", ['{"id": 4, "question": "sell", "yes": "no"}', '{"id": 4, "question": "lend", '
                                  '"yes": true}', '{"id": "4", "question": "sell", "yes": true}', '{"id": 4}', "yes"])
def test_a_malformed_answer_is_a_wire_error_and_settles_nothing(text):
    d = Decisions(lambda t: None)
    d.ask(4, "sell", {})
    with pytest.raises(wire.WireError):
        d.answer(text)
    assert d.answer('{"id": 4, "question": "sell", "yes": true}') == (4, "sell", True)


def test_an_unanswered_question_gets_the_behaviours_answer_after_the_timeout():
    clock = Clock()
    d = Decisions(lambda t: None, timeout=5.0, clock=clock)
    d.ask(1, "buy", {})
    clock.now = 3.0
    d.ask(1, "buy", {})  # asked again: the timeout still runs from the first time
    d.ask(2, "sell", {})
    assert d.expired() == []
    clock.now = 5.0
    assert d.expired() == [(1, "buy")]
    assert d.answer('{"id": 1, "question": "buy", "yes": false}') is None  # too late: already settled
    clock.now = 8.0
    assert d.expired() == [(2, "sell")]
