"""The original simulator's classes are mapped to what they did there (docs/model.md §10)."""
import json

import pytest

import infomarket as im
from infomarket.config.legacy import from_legacy
from infomarket.registry import get_behaviour

from .config.test_legacy import legacy
from .shared_kernel import simulate


def test_free_rider_maps_to_the_originals_sceptical_free_rider():
    data = legacy(behaviors=[{"class": "ScepticalBehavior", "population_size": 24, "parameters": {}},
                             {"class": "FreeRiderBehavior", "population_size": 1, "parameters": {}}])
    groups = from_legacy(data, "x")["swarm"]["groups"]
    assert [(g["behaviour"], g["count"]) for g in groups] == [("sceptical", 24), ("sceptical_free_rider", 1)]


def test_sceptical_free_rider_buys_sceptically_and_never_sells(tmp_path):
    spec = get_behaviour("sceptical_free_rider")
    assert spec.buy.py_func is get_behaviour("sceptical").buy.py_func and not spec.honest
    p = tmp_path / "free.json"
    p.write_text(json.dumps(legacy(behaviors=[
        {"class": "NaiveBehavior", "population_size": 20, "parameters": {}},
        {"class": "FreeRiderBehavior", "population_size": 5, "parameters": {"threshold": 0.25}}])))
    cfg = im.load_experiment(p).with_overrides(steps=3000, transitory=0)
    ev = simulate(cfg, seed=2, record_events=True).events  # built-in rules: on the shared kernel
    bought = ev[(ev.kind == "purchase") & (ev.buyer >= 20)]
    assert len(bought) > 0 and not (ev.seller >= 20).any()  # they buy, nobody ever buys from them
    # sceptics buy several offers per site and step; naive buyers at most one
    assert bought.groupby(["step", "buyer", "site"]).size().max() > 1


def test_a_stake_under_delayed_payment_is_refused_like_the_original(tmp_path):
    p = tmp_path / "delayed.json"
    p.write_text(json.dumps(legacy(payment_system={
        "class": "DelayedPaymentPaymentSystem", "initial_reward": 1,
        "parameters": {"information_share": 0.5, "stake_amount": 0.04}})))
    with pytest.raises(im.ConfigError, match="stake_amount"):
        im.load_experiment(p)


def test_a_stake_under_outlier_penalisation_is_read():
    data = legacy(payment_system={"class": "OutlierPenalisationPaymentSystem", "initial_reward": 1,
                                  "parameters": {"information_share": 0.5, "stake_amount": 0.07}})
    assert from_legacy(data, "x")["payment"]["stake"] == 0.07
