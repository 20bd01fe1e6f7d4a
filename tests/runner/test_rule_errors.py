"""A user's rule that raises while it runs, or that cannot be compiled into the step, is named: the rule,
its file and line, and the step; one message, exit 2, no traceback, nothing half-written (issue 21).

Before: a division by zero in a sell rule swept on a process pool gave a 44-line _RemoteTraceback naming
neither rule nor step (and `run`/`sweep` exited 1 with "ZeroDivisionError: division by zero"); a sell rule
returning three values gave numba's "Cannot unify Tuple" pointing into the generated kernel; a string
default gave "could not convert string to float" naming no rule or parameter."""
from __future__ import annotations

import textwrap

import numpy as np
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.store import Store

HEAD = '''
import infomarket as im
from infomarket.behaviours.api import own_entry
'''

# raises at step 37 exactly (the clock counts the step before any rule runs): a hand-chosen step.  It takes
# the run's `rng` (and draws nothing) so that it is asked every step, with a neighbour or without one
# (docs/extending.md): a rule without `rng` is asked only when some robot could buy its offer
LATE = HEAD + '''

@im.behaviour("late_divider", buy="naive", honest=False, description="divides by k at step 37")
def late_divider_sell(w, me, site, rng, k=0.0):
    valid, x, y, age = own_entry(w, me, site)
    if w.clock[0] == 37:
        x = x / k
    return valid, x, y, age
'''

THREE = HEAD + '''

@im.behaviour("three_values", buy="naive", honest=False, description="returns three values")
def three_values_sell(w, me, site):
    valid, x, y, age = own_entry(w, me, site)
    return valid, x, y
'''

STRING = HEAD + '''

@im.behaviour("string_default", buy="naive", honest=False, description="a text default")
def string_default_sell(w, me, site, mode="fast"):
    return own_entry(w, me, site)
'''

# k = 0 raises at the first paid deposit; k = -1 gives every weight -1: one weight rule, one step kernel for
# the two tests (a kernel's name hashes its rules' file and source, not their parameters)
PAY = '''
import infomarket as im


@im.payment("divided", description="divides by a parameter")
def divided(buyer, sellers, sites, directions, weights, k=0.0):
    for x in range(len(sellers)):
        weights[x] = 1.0 / k
'''


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """A folder for the plugins several tests load: one file, one registered rule and so one step kernel
    per test process for all of them (a kernel's name hashes its rules' file and source)."""
    return tmp_path_factory.mktemp("plugins")


def experiment(tmp_path, name: str, plugin: str, behaviour: str = "naive", scheme: str = "delayed",
               steps: int = 200, runs: int = 2, robots: int = 6, plugins=None, k: float | None = None) -> str:
    """The experiment ``name``, its plugin written as ``name.py`` in ``plugins`` (default ``tmp_path``; kept
    when it is there already) and its file in ``tmp_path``; ``k``: the payment scheme's parameter."""
    path = (plugins or tmp_path) / f"{name}.py"
    if not path.exists():
        path.write_text(plugin)
    (tmp_path / f"{name}.toml").write_text(textwrap.dedent(f'''
        name = "{name}"
        steps = {steps}
        runs = {runs}
        seed = 4
        plugins = ["{path}"]

        [swarm]
        robots = {robots}

        [[swarm.groups]]
        behaviour = "naive"
        count = {robots - 1}

        [[swarm.groups]]
        behaviour = "{behaviour}"
        count = 1

        [payment]
        scheme = "{scheme}"
        ''') + (f"params = {{ k = {k} }}\n" if k is not None else ""))
    return str(tmp_path / f"{name}.toml")


def one_message(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("infomarket: error:") == 1, err
    assert "Traceback" not in err and "_RemoteTraceback" not in err, err
    return err


def line_of(path, text: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if text in ln)


def test_a_rule_raising_in_a_process_pool_sweep_is_named_with_its_line_and_step(tmp_path, shared, capsys):
    exp = experiment(tmp_path, "late", LATE, "late_divider", plugins=shared)
    out = tmp_path / "store"
    assert main(["sweep", exp, "--out", str(out), "--workers", "2", "--quiet"]) == 2
    err = one_message(capsys)
    at = f"{shared / 'late.py'}:{line_of(shared / 'late.py', 'x = x / k')}"
    assert (f"behaviour 'late_divider': its sell rule late_divider_sell raised ZeroDivisionError "
            f"(division by zero) at step 37 (robot 5, site 0), at {at}") in err
    failed = Store(out).failed()  # committed as failed, with the same one-line message
    assert len(failed) == 2 and all(e.startswith("behaviour 'late_divider'") and "\n" not in e
                                    for e in failed.error)


def test_infomarket_run_names_the_rule_too(tmp_path, shared, capsys):
    exp = experiment(tmp_path, "late", LATE, "late_divider", runs=1, plugins=shared)
    assert main(["run", exp, "--out", str(tmp_path / "store"), "--quiet"]) == 2
    assert "late_divider_sell raised ZeroDivisionError (division by zero) at step 37" in one_message(capsys)


def _first_paid_deposit(cfg, seed: int) -> int:
    """The first step at which a robot deposits with transactions open: the first call of the weight rule.
    From the event log of the same run under the delayed scheme (weights do not move robots)."""
    data = cfg.model_dump()
    data["payment"].update(scheme="delayed", params={})
    res = im.simulate(im.config.validate(data), seed, record_events=True)
    open_tx: dict[int, int] = {}
    for ev in res.events.itertuples():
        if ev.kind == "purchase":
            open_tx[ev.buyer] = open_tx.get(ev.buyer, 0) + 1
        elif ev.kind == "deposit":
            if open_tx.get(ev.buyer, 0):
                return int(ev.step)
            open_tx[ev.buyer] = 0
    raise AssertionError("no paid deposit")


def test_a_weight_rule_raising_at_a_deposit_is_named_with_the_step(tmp_path, shared, capsys):
    exp = experiment(tmp_path, "divided", PAY, scheme="divided", steps=2000, runs=1, robots=25, plugins=shared, k=0.0)
    out = tmp_path / "store"
    assert main(["sweep", exp, "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = one_message(capsys)
    cfg = im.load_experiment(exp)
    seed = int(Store(out).runs().seed.iloc[0])
    step = _first_paid_deposit(cfg, seed)
    at = f"{shared / 'divided.py'}:{line_of(shared / 'divided.py', 'weights[x] = 1.0 / k')}"
    assert "payment scheme 'divided': its weight rule divided raised ZeroDivisionError" in err
    assert f"at step {step} (buyer " in err and at in err


def test_a_rule_returning_three_values_is_refused_before_anything_is_written(tmp_path, shared, capsys):
    exp = experiment(tmp_path, "three", THREE, "three_values", plugins=shared)
    out = tmp_path / "store"
    assert main(["sweep", exp, "--out", str(out), "--quiet"]) == 2
    err = one_message(capsys)
    line = line_of(shared / "three.py", "@im.behaviour")
    assert (f"behaviour 'three_values': its sell rule three_values_sell ({shared / 'three.py'}:{line}) returns "
            f"3 values") in err
    assert "a sell rule returns 4: (valid, x, y, age)" in err and "Cannot unify" not in err
    assert not out.exists()
    assert main(["run", exp, "--out", str(out), "--quiet"]) == 2
    assert "three_values_sell" in one_message(capsys) and not out.exists()


TEXT_AGE = HEAD + '''

@im.behaviour("text_age", buy="naive", honest=False, description="returns a text age")
def text_age_sell(w, me, site):
    valid, x, y, age = own_entry(w, me, site)
    return valid, x, y, "old"
'''


def test_a_rule_returning_four_values_of_the_wrong_kinds_is_refused_naming_it(tmp_path, capsys):
    """Four values, one of them text: it compiles alone, so only its return types tell (it gave numba's
    "During: Pass nopython_type_inference" and exit 1)."""
    exp = experiment(tmp_path, "textage", TEXT_AGE, "text_age")
    out = tmp_path / "store"
    assert main(["run", exp, "--out", str(out), "--quiet"]) == 2
    err = one_message(capsys)
    assert "behaviour 'text_age': its sell rule text_age_sell" in err and "a sell rule returns 4 numbers" in err
    assert "nopython" not in err and not out.exists()


def test_a_text_default_is_refused_naming_the_rule_and_the_parameter(tmp_path, capsys):
    exp = experiment(tmp_path, "text", STRING, "string_default")
    assert main(["check", exp]) == 2
    err = one_message(capsys)
    at = f"{tmp_path / 'text.py'}:{line_of(tmp_path / 'text.py', '@im.behaviour')}"
    assert f"sell rule string_default_sell ({at}): parameter 'mode' has the default 'fast'" in err
    assert "could not convert" not in err


@pytest.mark.parametrize("default", ["float('nan')", "True", "None", "[1.0]"])
def test_defaults_that_are_not_finite_numbers_are_refused(default):
    from infomarket.errors import RuleError
    from infomarket.registry import register_behaviour

    scope: dict = {}
    exec(f"def bad_sell(w, me, site, p={default}):\n    return True, 0.0, 0.0, 0\n", scope)
    with pytest.raises(RuleError, match="parameter 'p' has the default"):
        register_behaviour(f"bad_default_{abs(hash(default))}", buy="naive", sell=scope["bad_sell"], honest=True)


def test_replay_names_the_rule_and_writes_nothing(tmp_path, shared, capsys):
    exp = experiment(tmp_path, "late", LATE, "late_divider", plugins=shared)
    out = tmp_path / "late.html"
    assert main(["replay", exp, "--out", str(out), "--steps", "100", "--quiet"]) == 2
    assert "late_divider_sell raised ZeroDivisionError (division by zero) at step 37" in one_message(capsys)
    assert not out.exists()
    assert not np.any([p.name.startswith(".late") for p in tmp_path.iterdir()])  # no temporary file left


def test_a_weight_rule_giving_negative_weights_is_named_with_the_step(tmp_path, shared, capsys):
    """Before: "step N: a payment rule returned a negative or non-finite weight", naming no scheme, exit 1.
    The dividing rule with k = -1: every weight -1, no error raised."""
    exp = experiment(tmp_path, "divided", PAY, scheme="divided", steps=2000, runs=1, robots=25, plugins=shared, k=-1.0)
    out = tmp_path / "store"
    assert main(["sweep", exp, "--out", str(out), "--workers", "1", "--quiet"]) == 2
    err = one_message(capsys)
    cfg = im.load_experiment(exp)
    step = _first_paid_deposit(cfg, int(Store(out).runs().seed.iloc[0]))
    at = f"{shared / 'divided.py'}:{line_of(shared / 'divided.py', '@im.payment')}"
    assert (f"payment scheme 'divided': its weight rule divided ({at}) gave a negative or "
            f"non-finite weight at step {step}") in err


def test_the_python_api_names_the_rule_and_the_step_too(tmp_path, shared):
    """``im.simulate`` / ``Simulation.step`` raise the same RuleRunError as the command line (they raised
    numba's bare ZeroDivisionError, or its typing error pointing into the generated kernel)."""
    from infomarket import plugins
    from infomarket.errors import RuleRunError

    exp = experiment(tmp_path, "late", LATE, "late_divider", runs=1, plugins=shared)
    plugins.load(str(shared / "late.py"))
    with pytest.raises(RuleRunError) as err:
        im.simulate(exp, seed=3)
    at = f"{shared / 'late.py'}:{line_of(shared / 'late.py', 'x = x / k')}"
    assert "its sell rule late_divider_sell raised ZeroDivisionError (division by zero) at step 37" in str(err.value)
    assert at in str(err.value)

    exp = experiment(tmp_path, "three", THREE, "three_values", runs=1, plugins=shared)
    plugins.load(str(shared / "three.py"))
    with pytest.raises(RuleRunError, match="three_values_sell.*returns 3 values"):
        im.Simulation(exp, seed=3)


def test_a_rule_raising_in_one_run_of_a_batch_leaves_that_run_marked(tmp_path, shared):
    # the kernel's step_all leaves -1 on the world whose step raised (Simulations names that run): the
    # first world stops at step 30, before the rule divides, the second reaches step 37
    from infomarket.engine.batch import Simulations

    cfg = im.load_experiment(experiment(tmp_path, "late", LATE, "late_divider", plugins=shared))
    sims = Simulations(cfg, [11, 12])
    status, clocks = np.zeros(2, np.int64), np.zeros(2, np.int64)
    with pytest.raises(ZeroDivisionError):
        sims.kernel.step_all(sims._views, sims._rngs, np.array([30, 40]), status, clocks)
    assert status.tolist() == [sims.kernel.DONE, -1] and clocks[0] == 30
