"""The built-in behaviours and payment schemes, registered through the public API users call.

This module is the one place that registers them (the rule modules only define functions), and the
registry never imports it: ``infomarket/__init__.py`` does, so the built-ins exist as soon as the package
is imported and there is no import circle between the registry and the rules.  The order below is the
order ``infomarket list`` shows.
"""
from .behaviours import byzantine, naive, sceptical, waypoint
from .payments import schemes
from .registry import register_behaviour, register_payment

register_behaviour("naive", buy=naive.naive_buy, sell=naive.honest_sell, honest=True,
                   description="buys younger information and averages it in; sells its own entry")
register_behaviour("sceptical", buy=sceptical.sceptical_buy, sell="naive", honest=True,
                   description="waits for a second, agreeing piece of information before using it",
                   limits={"threshold": ("> 0", lambda v: v > 0)})
register_behaviour("saboteur", buy="naive", sell=byzantine.rotated_sell, honest=False,
                   description="naive buyer that sells vectors rotated by rotation_angle")
register_behaviour("scaboteur", buy="sceptical", sell=byzantine.rotated_sell, honest=False,
                   description="sceptical buyer that sells vectors rotated by rotation_angle")
register_behaviour("greedy", buy="naive", sell=byzantine.greedy_sell, honest=False,
                   description="naive buyer that sells its entry claiming age 1")
register_behaviour("free_rider", buy="naive", sell=byzantine.free_rider_sell, honest=False,
                   description="naive buyer that never sells")
register_behaviour("sceptical_free_rider", buy="sceptical", sell=byzantine.free_rider_sell, honest=False,
                   description="sceptical buyer that never sells (the original's FreeRiderBehavior)")
register_behaviour("waypoint", buy=waypoint.waypoint_buy, sell="naive", honest=True, paths=True,
                   description="naive buyer that buys and follows waypoint paths once a straight line failed it")

register_payment("delayed", schemes.delayed_weights,
                 description="sellers share information_share * reward per transaction")
register_payment("outlier", schemes.outlier_weights,
                 description="sellers share information_share * reward + stakes by similarity weight",
                 limits={"theta": ("in (0, 180]", lambda v: 0 < v <= 180)})
