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
    (dict(needs_neighbours=1), RegistrationError, ["needs_neighbours must be True or False"]),
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


@pytest.mark.parametrize("files, entry, words", [
    ({"exits.py": "import sys\nsys.exit(3)\n"}, "exits.py", ["called sys.exit(3) while being imported"]),
    ({"folder.py/x": ""}, "folder.py", ["folder.py is not a file"]),
    ({"notes.txt": "x = 1\n"}, "notes.txt", ["notes.txt is a file but not a .py file"]),
    ({}, "/etc/passwd", ["/etc/passwd is a file but not a .py file"]),
    ({}, "/no/such/module", ["'/no/such/module' is neither a .py file nor a module name"]),
    ({}, "a b", ["'a b' is neither a .py file nor a module name"]),
])
def test_plugins_that_cannot_be_imported_give_one_message(tmp_path, monkeypatch, capsys, files, entry, words):
    """Before: a plugin calling sys.exit ended `infomarket check` silently with its code; a folder or a
    text file gave "No module named ..."."""
    from infomarket.cli import main

    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    (tmp_path / "e.toml").write_text(f'name = "e"\nplugins = ["{entry}"]\n[swarm]\nrobots = 2\n'
                                     '[[swarm.groups]]\nbehaviour = "naive"\ncount = 2\n')
    monkeypatch.chdir(tmp_path)
    assert main(["check", "e.toml"]) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error:") == 1 and "Traceback" not in err
    for w in words:
        assert w in err, err
