"""Experiment configuration: schema, file loading (TOML and the original JSON), validation errors."""
from .load import load_experiment, shipped_experiments, validate
from .schema import Experiment, Group, Payment, Swarm

__all__ = ["Experiment", "Group", "Payment", "Swarm", "load_experiment", "shipped_experiments", "validate"]
