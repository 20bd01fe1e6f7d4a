"""Adversary search: the worst attack found against each defence, by a global search (CMA-ES restarted
from start points spread over the attacker's parameter space) beside a random search and the baselines,
raced on shared selection seeds and confirmed on seeds no other phase uses.  Every evaluation is a set of
conditions of a results store, run on the sweep machinery.

Modules: ``space`` (the parameter vector and its ranges), ``objective`` (what a run is worth to the
attacker), ``study`` (cells, declared settings and baselines), ``baselines`` (the rotation grid),
``restarts`` (start points, CMA-ES restarts, random search), ``racing`` (successive halving), ``driver``
(one cell's phases, resumable), ``summary`` (the frames and a short summary a search leaves),
``report`` (the study's answers), ``cli`` (``infomarket attack-search``).  See docs/attack-search.md.
"""
