"""Adversary search: CMA-ES over the parameterised `attacker` to find the worst attack each
defence faces, each candidate evaluated as conditions of a results store on the sweep machinery.

Modules: ``space`` (the parameter vector and its ranges), ``objective`` (what a run is worth to the
attacker), ``study`` (cells, baselines and declared settings), ``driver`` (the resumable CMA-ES loop),
``report`` (held-out comparisons with intervals), ``cli`` (``infomarket attack-search``).  See
docs/attack-search.md.
"""
