"""The original simulator's JSON format is accepted unchanged."""
import json
import os
from pathlib import Path

import pytest

from infomarket.config import load_experiment

#: A folder holding the original simulator's configuration files (not part of this project), to check
#: that every one of them loads: e.g. ``INFOMARKET_REFERENCE_CONFIGS=/path/to/reference-configs``.
REFERENCE = os.environ.get("INFOMARKET_REFERENCE_CONFIGS")


def legacy(**over):
    """An original-format file written here from docs/model.md §10 (Fig. 4B-like)."""
    data = {
        "width": 1200, "height": 600, "food": {"x": 200, "y": 300, "radius": 50},
        "nest": {"x": 1000, "y": 300, "radius": 50}, "simulation_steps": 30000, "transitory_period": 20000,
        "number_runs": 32, "visualization": {"activate": False, "fps": 60},
        "random_walk": {"random_walk_factor": 0.9, "levi_factor": 1.4},
        "agent": {"radius": 8, "speed": 2.5, "communication_radius": 50, "communication_stop_time": 0,
                  "communication_cooldown": 0, "noise_sampling_mu": 0.05, "noise_sampling_sigma": 0.05,
                  "noise_sd": 0.05, "fuel_cost": 0},
        "behaviors": [{"class": "NaiveBehavior", "population_size": 0, "parameters": {}},
                      {"class": "ScepticalBehavior", "population_size": 22, "parameters": {"threshold": 0.25}},
                      {"class": "ScaboteurBehavior", "population_size": 3,
                       "parameters": {"rotation_angle": 40, "threshold": 0.25}}],
        "payment_system": {"class": "OutlierPenalisationPaymentSystem", "initial_reward": 1,
                           "parameters": {"information_share": 0.5}},
        "market": {"class": "FixedPriceMarket", "parameters": {"reward": 1}},
        "data_collection": {"output_directory": "x", "filename": "y.csv", "metrics": ["rewards"],
                            "precision_recording": True, "precision_recording_interval": 100},
    }
    data.update(over)
    return data


def test_translation(tmp_path):
    p = tmp_path / "config22-3_40.json"
    p.write_text(json.dumps(legacy()))
    cfg = load_experiment(p)
    assert cfg.name == "config22-3_40" and cfg.steps == 30000 and cfg.transitory == 20000 and cfg.runs == 32
    assert [(g.behaviour, g.count) for g in cfg.swarm.groups] == [("sceptical", 22), ("scaboteur", 3)]
    assert cfg.swarm.groups[1].params == {"rotation_angle": 40, "threshold": 0.25}
    assert cfg.payment.scheme == "outlier" and cfg.payment.stake == 0.04  # the original's default stake
    assert cfg.history_every == 100


def test_explicit_zero_stake_and_delayed(tmp_path):
    p = tmp_path / "a.json"
    p.write_text(json.dumps(legacy(payment_system={"class": "DelayedPaymentPaymentSystem", "initial_reward": 3,
                                                   "parameters": {"information_share": 0.5}})))
    cfg = load_experiment(p)
    assert cfg.payment.scheme == "delayed" and cfg.payment.stake == 0.0 and cfg.payment.initial_wealth == 3


@pytest.mark.skipif(not REFERENCE,
                    reason="INFOMARKET_REFERENCE_CONFIGS names no folder of original configuration files")
def test_every_reference_config_is_accepted():
    folder = Path(REFERENCE)
    assert folder.is_dir(), f"INFOMARKET_REFERENCE_CONFIGS={REFERENCE}: not a folder"
    files = sorted(folder.rglob("*.json"))
    assert len(files) >= 50
    for f in files:
        cfg = load_experiment(f)
        assert cfg.swarm.robots == 25
