"""Which deposits count: the transitory boundary, pinned to the original simulator's rule."""
import numpy as np

import infomarket as im

from ..shared_kernel import simulate
from .test_reference import SETUP


def deposit_steps(cfg, seed):
    ev = simulate(cfg, seed, record_events=True).events  # the shared kernel (test_reference's mix)
    return ev[ev.kind == "deposit"].step.to_numpy()


def test_an_item_deposited_at_the_last_transitory_step_counts():
    cfg = im.Experiment.model_validate({**SETUP, "steps": 1200, "transitory": 0})
    steps = deposit_steps(cfg, 11)
    boundary = int(steps[len(steps) // 2])  # a step at which a deposit happens
    # the transitory period changes only what is counted, never the dynamics
    bounded = cfg.with_overrides(transitory=boundary)
    assert np.array_equal(deposit_steps(bounded, 11), steps)
    items = int(simulate(bounded, 11).robots.items_collected.sum())
    assert items == int((steps >= boundary).sum())
