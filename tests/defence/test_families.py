"""Defence families: parameter scales, the declared file's checks, and the configurations candidates write."""
import dataclasses
import math

import numpy as np
import pytest

from infomarket.config import load_experiment
from infomarket.defence import study
from infomarket.defence.families import (EXISTING, Candidate, Param, candidates, configure, existing,
                                         parse_family, refine)
from infomarket.errors import ConfigError


def test_a_whole_number_parameter_gives_each_number_an_equal_share_of_the_unit_interval():
    p = Param("vectors", ("x",), 2, 9, "int")  # 8 numbers: each owns 1/8 of [0, 1]
    assert [p.value(u) for u in (0.0, 0.124, 0.125, 0.5, 0.874, 0.875, 1.0)] == [2, 2, 3, 6, 8, 9, 9]
    assert p.unit(5) == pytest.approx(3.5 / 8) and p.value(p.unit(5)) == 5


def test_a_log_parameter_is_linear_in_the_logarithm_and_a_float_one_in_the_value():
    lg = Param("horizon", ("x",), 100, 10000, "log")
    assert lg.value(0.5) == pytest.approx(1000.0) and lg.value(0.25) == pytest.approx(10 ** 2.5)
    assert lg.unit(1000.0) == pytest.approx(0.5)
    fl = Param("power", ("x",), 0, 3)
    assert fl.value(0.25) == pytest.approx(0.75) and fl.unit(2.25) == pytest.approx(0.75)
    assert fl.value(-1) == 0 and fl.value(2) == 3  # clipped to the range


@pytest.mark.parametrize("table, words", [
    ({"nope": 1}, ["[families.f]", "unknown key 'nope'"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 0, "high": 1, "kind": "cubic"}}}, ["kind = 'cubic'"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 1, "high": 1}}}, ["params.a", "low must be below high"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 0, "high": 1, "kind": "log"}}}, ["both above 0"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 0.5, "high": 3, "kind": "int"}}}, ["both whole numbers"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 0, "high": 1, "default": 2}}}, ["default = 2 is outside"]),
    ({"params": {"a": {"low": 0, "high": 1}}}, ["params.a", "paths"]),
    ({"params": {"a": {"paths": "payment.stake", "low": "x", "high": 1}}}, ["low", "'x'"]),
    ({"params": {"a": {"paths": "payment.stake", "low": 0, "high": 1, "step": 1}}}, ["unknown key 'step'"]),
])
def test_a_malformed_family_is_refused_naming_the_key(table, words):
    with pytest.raises(ConfigError) as e:
        parse_family("f", table, "q.toml")
    assert all(w in str(e.value) for w in words), str(e.value)


def test_the_existing_defences_name_is_reserved():
    with pytest.raises(ConfigError, match="existing"):
        parse_family(EXISTING, {}, "q.toml")


def _theta_family():
    return parse_family("theta", {"set": {"swarm.groups[0].behaviour": "sceptical", "payment.scheme": "outlier"},
                                  "params": {"theta": {"paths": ["payment.params.theta",
                                                                 "swarm.groups[1].params.theta"],
                                                       "low": 10, "high": 40, "default": 30}}}, "q.toml")


def test_a_candidate_writes_its_value_to_every_path_and_the_counts_to_the_groups():
    exp = load_experiment("attack_search")
    fam = _theta_family()
    c = Candidate("theta9", "theta", {"theta": 17.5})
    cfg = configure(exp.model_dump(), 3, 25, c.settings({"theta": fam}), "test")
    assert cfg.payment.params["theta"] == 17.5 and cfg.swarm.groups[1].params["theta"] == 17.5
    assert [g.count for g in cfg.swarm.groups] == [22, 3] and cfg.sweep is None
    none = configure(exp.model_dump(), 0, 25, c.settings({"theta": fam}), "test")
    assert [g.count for g in none.swarm.groups] == [25, 0]


def test_an_existing_defence_is_its_axis_settings():
    exp = load_experiment("attack_search")
    have = existing(exp)
    assert "staking" in have and "weighted" in have
    c = Candidate("weighted", EXISTING, set=have["weighted"], origin="existing")
    cfg = configure(exp.model_dump(), 3, 25, c.settings({}), "test")
    assert cfg.swarm.groups[0].behaviour == "reputation_weighted" and cfg.swarm.groups[0].params == {"power": 2.0}


def test_the_first_candidate_is_the_default_and_the_design_is_a_function_of_the_seed():
    fam = _theta_family()
    a, b, c = candidates(fam, 5, 11), candidates(fam, 5, 11), candidates(fam, 5, 12)
    assert a[0].values == {"theta": 30.0} and a[0].origin == "default"
    assert [x.values for x in a] == [x.values for x in b] and [x.values for x in a] != [x.values for x in c]
    assert [x.label for x in a] == [f"theta{k}" for k in range(5)]
    assert all(10 <= x.values["theta"] <= 40 for x in a)
    assert len({x.values["theta"] for x in a}) == 5


def test_refinement_stays_near_the_best_and_in_range_and_continues_the_labels():
    fam = _theta_family()
    best = Candidate("theta3", "theta", {"theta": 12.0})
    r = refine(fam, best, 40, 5, 11, 0.1)
    assert [x.label for x in r] == [f"theta{k}" for k in range(5, 45)] and all(x.origin == "refine" for x in r)
    v = np.array([x.values["theta"] for x in r])
    assert v.min() >= 10 and v.max() <= 40
    # steps of 0.1 of the unit cube are 3 degrees here: 40 draws stay within 5 sd, and some are clipped at 10
    assert np.all(np.abs(v - 12.0) <= 15.0) and np.any(v == 10.0)
    assert refine(fam, best, 40, 5, 11, 0.1)[7].values == r[7].values


def test_the_floor_is_f_over_n_minus_2f_and_none_once_half_lie():
    assert study.floor(1, 6) == pytest.approx(0.25) and study.floor(2, 6) == pytest.approx(1.0)
    assert study.floor(3, 25) == pytest.approx(3 / 19) and math.isinf(study.floor(3, 6))


def test_the_shipped_study_builds_every_configuration_it_will_run():
    st = study.load(load_experiment("attack_search"))
    assert st.byzantines == (1, 3, 8) and st.settings.target == 3
    assert set(st.families) >= {"robust_median", "robust_trimmed", "robust_geometric", "sceptic_slash"}
    every = [c for f in st.families.values() for c in candidates(f, st.settings.candidates, st.settings.seed)]
    study.check(st, every + st.existing_candidates())
    assert st.undefended_config().swarm.groups[0].behaviour == "naive"


def test_a_family_whose_labels_would_be_an_existing_defences_is_refused():
    decl = study.read(None)
    data = {**decl.data, "families": {"theta": {"set": {}, "params": {"t": {"paths": "payment.params.theta",
                                                                          "low": 10, "high": 40}}}}}
    exp = load_experiment("attack_search")
    # theta20 and theta26 are existing defences: 30 candidates would label one of them theta20
    with pytest.raises(ConfigError, match="'theta20', an existing defence"):
        study.load(exp, dataclasses.replace(decl, data={**data, "defence": {**data["defence"], "candidates": 30}}))
    study.load(exp, dataclasses.replace(decl, data=data))  # 8 + 4 candidates: theta0 .. theta11, no clash
    bad = {**data, "families": {"a b": data["families"]["theta"]}}
    with pytest.raises(ConfigError, match="letters, digits and _"):
        study.load(exp, dataclasses.replace(decl, data=bad))
