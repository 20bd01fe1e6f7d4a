"""The search space maps every hand-written attack to a point that maps back to it, away from its gates."""
import numpy as np
import pytest

from infomarket.behaviours.attacks import POLICY
from infomarket.search import space
from infomarket.search.study import load_declarations

HAND = {n: b["params"] for n, b in load_declarations()["baselines"].items()}


@pytest.mark.parametrize("name", sorted(HAND))
def test_every_hand_written_attack_is_a_point_of_the_space(name):
    z = space.to_unit(HAND[name])
    assert ((0 <= z) & (z <= 1)).all()
    defaults = {p[0]: p[1] for p in POLICY}
    assert space.to_params(z) == {**defaults, **HAND[name]}


def test_a_small_step_from_the_constant_liar_leaves_its_gates_off():
    z = space.to_unit({"rot_base": 20.0})
    p = space.to_params(z + 0.2 * np.array([(-1) ** k for k in range(len(z))]))
    assert (p["fresh_record"], p["lie_min_record"], p["buyer_age_min"], p["lie_from_rep"]) == (0, 0, 0, 0)
    assert (p["max_confirmers"], p["cap_theta"], p["cap_sceptic"], p["withhold"], p["collude"]) == (24, 6, 100, 0, 0)
    assert p["rot_base"] == pytest.approx(20.0 + 0.2 * 180.0)


def test_every_point_gives_parameters_the_attacker_accepts():
    rng = np.random.default_rng(1)
    for z in rng.random((200, space.dimension())):
        for (name, _, lo, hi) in POLICY:
            assert lo <= space.to_params(z)[name] <= hi
