"""The Byzantine robots as agents: what they observe, the runs they act in, and the optimiser that tunes
their policy.

Both the reinforcement-learning interfaces (``infomarket.rl``: the Gymnasium and PettingZoo environments
and the evolution-strategies example) and the adaptive-attack search (``infomarket.search.adaptive``)
stand on this package, so neither depends on the other:

- ``observe``: the compiled observation, one row of numbers in [0, 1] per agent (``OBSERVATION``);
- ``runs``: B runs of one experiment stepped together in one compiled call (``Runs``), the agents'
  actions written into the attacker's parameters (``ACTIONS``);
- ``optim``: ``Adam``, the gradient step both trainings take.

Everything here needs only the core install (numpy and the compiled engine).
"""
