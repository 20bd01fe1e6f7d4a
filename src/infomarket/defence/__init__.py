"""Defence search: defences designed against the searched worst case (docs/defences.md, "Defence search").

``families`` (the parameter spaces), ``study`` (the declared settings, ``questions.toml``), ``driver``
(the outer search, each candidate judged by an inner attack search, then the frontier confirmed),
``report`` (the paired answers, the frontier and its figure), ``cli`` (``infomarket defence-search``).
"""
