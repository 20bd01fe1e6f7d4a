"""Byzantine behaviours: saboteurs sell rotated vectors; greedy robots oversell; free riders never sell."""
from ..engine.geometry import rotate
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

