"""How every study's report writes its numbers: JSON a strict parser reads, intervals as the reports print
them.  Here so that one study's report never imports another's to write the same things the same way.
"""
from __future__ import annotations

import math

import numpy as np


def json_ready(v):
    """JSON-ready: numpy scalars as Python numbers, NaN and infinities as null (strict JSON readers refuse
    ``NaN``), keys as strings.

    Example:
        >>> import numpy as np
        >>> from infomarket.analysis.formats import json_ready
        >>> json_ready({1: np.float64("nan"), "n": np.int64(3), "v": np.array([0.5])})
        {'1': None, 'n': 3, 'v': [0.5]}
    """
    if isinstance(v, dict):
        return {str(k): json_ready(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [json_ready(x) for x in v]
    if isinstance(v, np.ndarray):
        return json_ready(v.tolist())
    if isinstance(v, (np.integer, np.bool_)):
        return v.item()
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else None
    return v


def interval_text(lo: float, hi: float, fmt: str) -> str:
    """An interval as a report prints it: ``[lo, hi]`` in ``fmt``, or why it has no bounds.

    Example:
        >>> from infomarket.analysis.formats import interval_text
        >>> interval_text(0.015, 0.07, ".1%"), interval_text(float("-inf"), 0.2, ".2f")
        ('[1.5%, 7.0%]', 'unbounded')
    """
    if math.isnan(lo) or math.isnan(hi):
        return "undefined"
    return "unbounded" if not (math.isfinite(lo) and math.isfinite(hi)) else f"[{lo:{fmt}}, {hi:{fmt}}]"
