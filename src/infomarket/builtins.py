"""The built-in behaviours and payment schemes, registered through the public API users call.

This module is the one place that registers them (the rule modules only define functions), and the
registry never imports it: ``infomarket/__init__.py`` does, so the built-ins exist as soon as the package
is imported and there is no import circle between the registry and the rules.  The order below is the
order ``infomarket list`` shows.
"""
from .behaviours import byzantine, naive, sceptical, waypoint
from .payments import schemes
from .registry import register_behaviour, register_payment

#: the limit of every angle parameter (Theta, a rotation cap, a slash angle): degrees in (0, 180]
_ANGLE = ("in (0, 180]", lambda v: 0 < v <= 180)

register_behaviour("naive", buy=naive.naive_buy, sell=naive.honest_sell, honest=True, needs_neighbours=True,
                   description="buys younger information and averages it in; sells its own entry")
register_behaviour("sceptical", buy=sceptical.sceptical_buy, sell="naive", honest=True, needs_neighbours=True,
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
register_behaviour("waypoint", buy=waypoint.waypoint_buy, sell="naive", honest=True, paths=True, needs_neighbours=True,
                   description="naive buyer that buys and follows waypoint paths once a straight line failed it")

register_payment("delayed", schemes.delayed_weights,
                 description="sellers share information_share * reward per transaction")
register_payment("outlier", schemes.outlier_weights,
                 description="sellers share information_share * reward + stakes by similarity weight",
                 limits={"theta": _ANGLE})

# The paper's open questions (docs/research.md): rules that read the ledger's reputation record.
from .behaviours import reputation  # noqa: E402 - here: rules register in this order
from .payments import adaptive  # noqa: E402 - here: rules register in this order
from .payments import distinct  # noqa: E402 - here: rules register in this order

register_behaviour("reputation_sceptic", buy=reputation.reputation_sceptic_buy, sell="naive", honest=True,
                   needs_neighbours=True,
                   description="sceptical, but believes sellers with a high reputation or wealth share at once "
                               "and ignores sellers with a poor record",
                   limits={"threshold": ("> 0", lambda v: v > 0),
                           "min_record": (">= 0", lambda v: v >= 0),
                           "trust_reputation": ("in [0, 1]", lambda v: 0 <= v <= 1),
                           "distrust_reputation": ("in [0, 1]", lambda v: 0 <= v <= 1),
                           "trust_share": ("in [0, 1]", lambda v: 0 <= v <= 1)})
register_behaviour("reputation_farmer", buy="sceptical", sell=reputation.reputation_farmer_sell, honest=False,
                   description="sceptical buyer that sells the truth until its reputation or wealth share passes "
                               "a threshold, then vectors rotated by rotation_angle",
                   limits={"farm_record": (">= 0", lambda v: v >= 0),
                           "farm_reputation": ("in [0, 1]", lambda v: 0 <= v <= 1),
                           "farm_share": ("in [0, 1]", lambda v: 0 <= v <= 1)})
register_behaviour("theta_surfer", buy="sceptical", sell=reputation.theta_surfer_sell, honest=False,
                   description="sceptical buyer that lies by rotation_angle, capped at margin x the outlier "
                               "threshold the (adaptive = 1: adaptive) contract applies to it now",
                   limits={"margin": ("in (0, 1]", lambda v: 0 < v <= 1),
                           "theta": _ANGLE,
                           "theta_min": _ANGLE,
                           "adaptive": ("0 or 1", lambda v: v in (0, 1))})
register_payment("outlier_distinct", distinct.outlier_distinct_weights,
                 description="outlier penalisation counting sellers, not sales: a seller counts once in a "
                             "transaction's weight and its weight is split across its transactions",
                 limits={"theta": _ANGLE})
register_payment("adaptive_outlier", adaptive.adaptive_outlier_weights,
                 description="outlier penalisation with each seller's Theta between theta_min and theta by its "
                             "reputation",
                 limits={"theta": _ANGLE,
                         "theta_min": _ANGLE})

# The parameterised attack family, the threats the hand-written set lacked, and continuous trust.
from .behaviours import attacks, weighted  # noqa: E402 - here: rules register in this order

_UNIT = ("in [0, 1]", lambda v: 0 <= v <= 1)
_ANGLE = ("in [0, 180]", lambda v: 0 <= v <= 180)
_COUNT = (">= 0", lambda v: v >= 0)
register_behaviour("attacker", buy=attacks.policy_buy, sell=attacks.policy_sell, honest=False, needs_neighbours=True,
                   description="the parameterised attack (search space of `infomarket attack-search`): rotation as "
                               "a function of its record, its buyers, Θ and the sellers in range; gates; collusion",
                   limits={**{name: (f"in [{lo:g}, {hi:g}]", lambda v, lo=lo, hi=hi: lo <= v <= hi)
                              for name, _, lo, hi in attacks.POLICY},
                           "theta": _ANGLE,
                           "theta_min": _ANGLE,
                           "adaptive": ("0 or 1", lambda v: v in (0, 1)), "threshold": ("> 0", lambda v: v > 0)})
register_behaviour("colluder", buy=attacks.colluder_buy, sell=attacks.colluder_sell, honest=False,
                   needs_neighbours=True,
                   description="liars that agree on one rotation_angle and buy each other's offers to inflate their "
                               "records", limits={"rotation_angle": _ANGLE, "threshold": ("> 0", lambda v: v > 0)})
register_behaviour("newcomer", buy="sceptical", sell=attacks.newcomer_sell, honest=False,
                   description="identity reset: lies by rotation_angle while its record is shorter than "
                               "fresh_record settled sales, then withdraws (the engine has no rejoin)",
                   limits={"rotation_angle": _ANGLE, "fresh_record": _COUNT})
register_behaviour("selective_liar", buy="sceptical", sell=attacks.selective_sell, honest=False,
                   description="lies by rotation_angle only when at most max_confirmers other sellers are in range",
                   limits={"rotation_angle": _ANGLE, "max_confirmers": _COUNT})
register_behaviour("sceptic_surfer", buy="sceptical", sell=attacks.sceptic_surfer_sell, honest=False,
                   description="Θ-surfer aimed at the sceptic: lies by at most margin x the angle its confirmation "
                               "test accepts and margin x Θ",
                   limits={"rotation_angle": _ANGLE, "margin": ("in (0, 1]", lambda v: 0 < v <= 1),
                           "threshold": ("> 0", lambda v: v > 0), "theta": _ANGLE})
register_behaviour("tuned_farmer", buy="sceptical", sell=attacks.tuned_farmer_sell, honest=False,
                   description="reputation farmer tuned to the trust it targets: honest until farm_record settled "
                               "sales at reputation >= farm_reputation (the reputation sceptic's 10 and 0.85)",
                   limits={"rotation_angle": _ANGLE, "farm_reputation": _UNIT, "farm_record": _COUNT})
register_behaviour("reputation_weighted", buy=weighted.reputation_weighted_buy, sell="naive", honest=True,
                   needs_neighbours=True,
                   description="buys like the naive robot but averages a purchase in with its age weight times the "
                               "seller's reputation ** power (continuous trust)",
                   limits={"power": (">= 0", lambda v: v >= 0)})

# Robust buyers: a robust combination of the last purchases from distinct sellers (docs/defences.md).
from .behaviours import robust  # noqa: E402 - here: rules register in this order

_ROBUST = {"vectors": (">= 1", lambda v: v >= 1), "power": (">= 0", lambda v: v >= 0),
           "horizon": (">= 0", lambda v: v >= 0)}
register_behaviour("robust_median", buy=robust.robust_median_buy, sell="naive", honest=True,
                   description="holds its last `vectors` purchases per site from distinct sellers and steers by "
                               "their coordinate-wise median with its own entry", limits=_ROBUST)
register_behaviour("robust_trimmed", buy=robust.robust_trimmed_buy, sell="naive", honest=True,
                   description="as robust_median, with the coordinate-wise mean trimmed by `trim` at each end",
                   limits={**_ROBUST, "trim": (">= 0", lambda v: v >= 0)})
register_behaviour("robust_geometric", buy=robust.robust_geometric_buy, sell="naive", honest=True,
                   description="as robust_median, with the geometric median (`iterations` Weiszfeld steps)",
                   limits={**_ROBUST, "iterations": (">= 0", lambda v: v >= 0)})

# Market-side rules that give back or keep each seller's stake at settlement (docs/defences.md).
from .payments import consensus  # noqa: E402 - here: rules register in this order

register_payment("consensus_slash", consensus.consensus_slash_weights,
                 description="a record d degrees from its site's settled consensus (medoid) loses min(1, d / "
                             "slash_angle) of its stake and earns that much less of the share",
                 limits={"slash_angle": _ANGLE})
register_payment("capped_outlier", consensus.capped_outlier_weights,
                 description="outlier penalisation counting at most `cap` records per seller per round trip; "
                             "later ones are void: stake back, no pay",
                 limits={"theta": _ANGLE, "cap": (">= 1", lambda v: v >= 1)})

# Defences fed by trip outcomes, by vector ages and by votes (docs/defences.md, "Outcome, age and vote defences").
from .behaviours import fusion, outcome, vote  # noqa: E402 - here: rules register in this order

register_behaviour("outcome_trust", buy=outcome.outcome_trust_buy, sell="naive", honest=True,
                   description="keeps a Beta record of each seller fed by its own trips (site reached or nothing "
                               "found); skips sellers whose Beta mean is below `distrust` and weighs the rest by "
                               "it ** `power`; with `provenance` 1, of each vector's origin instead of its seller",
                   limits={"prior": ("> 0", lambda v: v > 0), "distrust": _UNIT, "power": (">= 0", lambda v: v >= 0),
                           "memory": (">= 1", lambda v: v >= 1), "provenance": ("0 or 1", lambda v: v in (0, 1))})
register_behaviour("gated_fusion", buy=fusion.gated_fusion_buy, sell="naive", honest=True, needs_neighbours=True,
                   description="fuses a purchase Kalman-style with variances from the vectors' ages (`drift` "
                               "degrees per step, `floor` units) and rejects it past a chi-square `gate`",
                   limits={"drift": (">= 0", lambda v: v >= 0), "floor": ("> 0", lambda v: v > 0),
                           "gate": ("> 0", lambda v: v > 0)})
register_behaviour("vote_k", buy=vote.vote_k_buy, sell="naive", honest=True,
                   description="with an invalid entry, buys from `k` distinct sellers and installs their "
                               "geometric (or coordinate-wise) median; with a valid one, the sceptic",
                   limits={"k": (">= 1 and <= 32", lambda v: 1 <= v <= 32),
                           "geometric": ("0 or 1", lambda v: v in (0, 1)), "iterations": (">= 0", lambda v: v >= 0),
                           "horizon": (">= 0", lambda v: v >= 0),
                           "threshold": ("> 0", lambda v: v > 0)})

# Slashing fed by trip outcomes: the buyer's outcome records decide the stakes (docs/defences.md).
from .payments import outcomes  # noqa: E402 - here: rules register in this order

register_payment("outcome_slash", outcomes.outcome_slash_weights,
                 description="a seller keeps (good + grace) / (good + bad + grace) of its stake by the buyer's "
                             "outcome record of it (outcome_trust buyers) and shares the rest by that times its "
                             "eq. 7 count",
                 limits={"theta": _ANGLE, "grace": ("> 0", lambda v: v > 0)})
register_payment("trip_slash", outcomes.trip_slash_weights,
                 description="each trip that failed on a seller's vector since the buyer's last settlement "
                             "(outcome_trust buyers) voids one of its records' stakes; the rest shared by eq. 7",
                 limits={"theta": _ANGLE})
