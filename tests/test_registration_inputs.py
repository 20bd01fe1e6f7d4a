"""Registration refuses, with one InfomarketError naming what is wrong, what it used to accept or crash on
(issue 21, "more of the same kinds"): names that cannot be written in an experiment file or printed
safely, builtins as rules, unknown rules to reuse, a non-boolean honest, and limits that name nothing."""
from __future__ import annotations

import pytest

from infomarket.errors import RegistrationError, RuleError
from infomarket.registry import behaviours, payments, register_behaviour, register_payment


def sell(w, me, site, k=1.0):
    return True, 0.0, 0.0, 0


def weights(buyer, sellers, sites, directions, weights, k=1.0):
    for x in range(len(sellers)):
        weights[x] = 1.0


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(name=""), RegistrationError, ["name ''", "1 to 64 letters"]),
    (dict(name="red\x1b[31m"), RegistrationError, ["1 to 64 letters"]),
    (dict(name="two words"), RegistrationError, ["1 to 64 letters"]),
    (dict(name="x" * 65), RegistrationError, ["1 to 64 letters"]),
    (dict(name="9lives"), RegistrationError, ["not starting with a digit"]),
    (dict(name="quote'd"), RegistrationError, ["1 to 64 letters"]),
    (dict(sell=len), RuleError, ["a rule must be a Python function", "len"]),
    (dict(buy="no_such_rule"), RegistrationError, ["buy='no_such_rule' names no registered behaviour", "naive"]),
    (dict(honest="no"), RegistrationError, ["honest must be True or False"]),
    (dict(limits={"zz": (">= 0", lambda v: v >= 0)}), RegistrationError, ["limits name 'zz'", "(k)"]),
    (dict(limits=5), RegistrationError, ["limits must be a dict"]),
    (dict(limits={"k": ">= 0"}), RegistrationError, ["the limit of 'k' must be (text, predicate)"]),
    (dict(description=5), RegistrationError, ["description must be text"]),
])
def test_behaviour_registrations_that_cannot_work_are_refused(kwargs, error, words):
    args = dict(name="fine_name", buy="naive", sell=sell, honest=True) | kwargs
    name = args.pop("name")
    with pytest.raises(error) as exc:
        register_behaviour(name, **args)
    for w in words:
        assert w in str(exc.value)
    assert name not in behaviours()


@pytest.mark.parametrize("name, rule, kwargs, error, words", [
    ("bad name", weights, {}, RegistrationError, ["1 to 64 letters"]),
    ("fine_scheme", max, {}, RuleError, ["a rule must be a Python function", "max"]),
    ("fine_scheme", weights, {"limits": {"theta": (">0", lambda v: v > 0)}}, RegistrationError,
     ["limits name 'theta'", "(k)"]),
])
def test_payment_registrations_that_cannot_work_are_refused(name, rule, kwargs, error, words):
    with pytest.raises(error) as exc:
        register_payment(name, rule, **kwargs)
    for w in words:
        assert w in str(exc.value)
    assert "fine_scheme" not in payments()


def test_a_good_registration_still_works():
    spec = register_behaviour("fine_registration", buy="naive", sell=sell, honest=False,
                              limits={"k": ("> 0", lambda v: v > 0)}, replace=True)
    assert spec.params == ("k",) and spec.check("k", -1.0) and not spec.honest
