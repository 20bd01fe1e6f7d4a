"""Byzantine behaviours: saboteurs sell rotated vectors; greedy robots oversell; free riders never sell."""
from ..engine.geometry import rotate
from ..registry import register_behaviour
from .api import own_entry


def rotated_sell(w, me, site, rotation_angle=90.0):
    """Sell the own entry rotated by ``rotation_angle`` degrees (the robot itself keeps the truth)."""
    valid, x, y, age = own_entry(w, me, site)
    rx, ry = rotate(x, y, rotation_angle)
    return valid, rx, ry, age


def greedy_sell(w, me, site):
    """Sell the own entry but claim it is one step old, to win every sale."""
    valid, x, y, age = own_entry(w, me, site)
    return valid, x, y, 1


def free_rider_sell(w, me, site):
    """Offer nothing."""
    return False, 0.0, 0.0, 0


register_behaviour("saboteur", buy="naive", sell=rotated_sell, honest=False,
                   description="naive buyer that sells vectors rotated by rotation_angle")
register_behaviour("scaboteur", buy="sceptical", sell=rotated_sell, honest=False,
                   description="sceptical buyer that sells vectors rotated by rotation_angle")
register_behaviour("greedy", buy="naive", sell=greedy_sell, honest=False,
                   description="naive buyer that sells its entry claiming age 1")
register_behaviour("free_rider", buy="naive", sell=free_rider_sell, honest=False,
                   description="naive buyer that never sells")
