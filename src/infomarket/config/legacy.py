"""The original simulator's JSON configuration format (docs/model.md §10), translated to ours.

Users of the original bring their files unchanged; every key is mapped or knowingly ignored, and an
unknown key is an error like in our own format.
"""
from __future__ import annotations

from typing import Any

from ..errors import ConfigError

BEHAVIOUR_CLASSES = {
    "NaiveBehavior": "naive",
    "SaboteurBehavior": "saboteur",
    "ScepticalBehavior": "sceptical",
    "ScaboteurBehavior": "scaboteur",
    "GreedyBehavior": "greedy",
    # The original's free rider buys sceptically and never sells (our "free_rider" buys naively).
    "FreeRiderBehavior": "sceptical_free_rider",
}
PAYMENT_CLASSES = {
    "DelayedPaymentPaymentSystem": ("delayed", 0.0),
    "OutlierPenalisationPaymentSystem": ("outlier", 0.04),  # the original's default stake
}
#: Parameters each original payment class accepts (the original rejects a stake for delayed payment).
PAYMENT_PARAMETERS = {
    "DelayedPaymentPaymentSystem": {"information_share"},
    "OutlierPenalisationPaymentSystem": {"information_share", "stake_amount"},
}
TOP_KEYS = {"width", "height", "food", "nest", "simulation_steps", "transitory_period", "number_runs",
            "visualization", "random_walk", "agent", "behaviors", "payment_system", "market",
            "data_collection"}
AGENT_KEYS = {"radius": "radius", "speed": "speed", "communication_radius": "communication_range",
              "noise_sampling_mu": "bias_mean", "noise_sampling_sigma": "bias_sd", "noise_sd": "noise_sd",
              "communication_stop_time": "stop_time", "communication_cooldown": "cooldown",
              "fuel_cost": "fuel_cost"}


def is_legacy(data: dict[str, Any]) -> bool:
    """Whether parsed JSON is in the original simulator's format (it has ``behaviors`` or ``simulation_steps``), to
    be translated."""
    return "behaviors" in data or "simulation_steps" in data


def _check_keys(where: str, got: dict, allowed) -> None:
    if not isinstance(got, dict):
        raise ConfigError(f"{where}: expected a JSON object, got {type(got).__name__}")
    unknown = sorted(set(got) - set(allowed))
    if unknown:
        raise ConfigError(f"{where or 'top level'}: unknown key(s) {', '.join(map(repr, unknown))}; "
                          f"allowed: {', '.join(sorted(allowed))}")


def _class_name(where: str, value: Any, allowed) -> str:
    """A ``class`` entry: a string naming one of ``allowed`` (a list or an object there is a type error)."""
    if value is None:
        raise ConfigError(f"{where}: missing; allowed: {', '.join(allowed)}")
    if not isinstance(value, str):
        raise ConfigError(f"{where}: expected the name of a class (a string), got {type(value).__name__} "
                          f"{str(value)[:80]}; allowed: {', '.join(allowed)}")
    return value


def from_legacy(data: dict[str, Any], name: str) -> dict[str, Any]:
    """Translate an original-format dictionary into our schema's dictionary (validated afterwards)."""
    _check_keys("", data, TOP_KEYS)
    out: dict[str, Any] = {"name": name}
    arena = {k: data[k] for k in ("width", "height") if k in data}
    if arena:
        out["arena"] = arena
    for site in ("food", "nest"):
        if site in data:
            _check_keys(site, data[site], {"x", "y", "radius"})
            out[site] = dict(data[site])
    for src, dst in (("simulation_steps", "steps"), ("transitory_period", "transitory"), ("number_runs", "runs")):
        if src in data:
            out[dst] = data[src]
    if "visualization" in data:
        _check_keys("visualization", data["visualization"], {"activate", "fps"})
    if "random_walk" in data:
        rw = data["random_walk"]
        _check_keys("random_walk", rw, {"random_walk_factor", "levi_factor"})
        out["random_walk"] = {dst: rw[src] for src, dst in (("random_walk_factor", "rho"), ("levi_factor", "alpha"))
                              if src in rw}
    if "agent" in data:
        _check_keys("agent", data["agent"], AGENT_KEYS)
        out["robot"] = {AGENT_KEYS[k]: v for k, v in data["agent"].items()}
    groups = []
    behaviors = data.get("behaviors", [])
    if not isinstance(behaviors, list):
        raise ConfigError("behaviors: expected a list of {class, population_size, parameters}")
    for k, b in enumerate(behaviors):
        _check_keys(f"behaviors[{k}]", b, {"class", "population_size", "parameters"})
        cls = _class_name(f"behaviors[{k}].class", b.get("class"), BEHAVIOUR_CLASSES)
        if cls not in BEHAVIOUR_CLASSES:
            raise ConfigError(f"behaviors[{k}].class: unknown class {cls!r}; allowed: "
                              f"{', '.join(BEHAVIOUR_CLASSES)}")
        count = b.get("population_size", 0)
        if count == 0:
            continue  # the original lists every class, most with population 0
        params = b.get("parameters", {})
        if not isinstance(params, dict):
            raise ConfigError(f"behaviors[{k}].parameters: expected a JSON object of parameter values, got "
                              f"{type(params).__name__}")
        groups.append({"behaviour": BEHAVIOUR_CLASSES[cls], "count": count, "params": params})
    if groups:
        total = sum(g["count"] for g in groups if isinstance(g["count"], int))
        out["swarm"] = {"robots": total, "groups": groups}
    else:
        raise ConfigError("behaviors: no behaviour has a population_size above 0; the swarm would be empty")
    payment: dict[str, Any] = {}
    if "payment_system" in data:
        ps = data["payment_system"]
        _check_keys("payment_system", ps, {"class", "initial_reward", "parameters"})
        cls = _class_name("payment_system.class", ps.get("class"), PAYMENT_CLASSES)
        if cls not in PAYMENT_CLASSES:
            raise ConfigError(f"payment_system.class: unknown class {cls!r}; allowed: {', '.join(PAYMENT_CLASSES)}")
        scheme, default_stake = PAYMENT_CLASSES[cls]
        params = ps.get("parameters", {})
        _check_keys("payment_system.parameters", params, PAYMENT_PARAMETERS[cls])
        params = dict(params)
        payment = {"scheme": scheme, "stake": params.pop("stake_amount", default_stake)}
        if "information_share" in params:
            payment["information_share"] = params["information_share"]
        if "initial_reward" in ps:
            payment["initial_wealth"] = ps["initial_reward"]
    if "market" in data:
        m = data["market"]
        _check_keys("market", m, {"class", "parameters"})
        if _class_name("market.class", m.get("class", "FixedPriceMarket"), ["FixedPriceMarket"]) != "FixedPriceMarket":
            raise ConfigError(f"market.class: unknown class {m.get('class')!r}; allowed: FixedPriceMarket")
        mp = m.get("parameters", {})
        _check_keys("market.parameters", mp, {"reward"})
        if "reward" in mp:
            payment["reward"] = mp["reward"]
    if payment:
        out["payment"] = payment
    if "data_collection" in data:
        dc = data["data_collection"]
        _check_keys("data_collection", dc, {"output_directory", "filename", "metrics", "precision_recording",
                                            "precision_recording_interval"})
        if dc.get("precision_recording"):
            out["history_every"] = dc.get("precision_recording_interval", 100)
    return out
