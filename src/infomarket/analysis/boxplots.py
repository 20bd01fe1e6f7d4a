"""Box plots drawn the way the paper's captions describe them (Fig. 2 caption).

Box = first to third quartile, line = median, whiskers to the last data point within 1.5 IQR of the
box, outliers as black diamonds; honest robots blue, Byzantine robots red.  Every box plot of the
report goes through ``draw_boxes`` so the convention is stated once.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Patch

HONEST = "#1f77b4"      # blue
BYZANTINE = "#d62728"   # red
WHISKER_IQR = 1.5


def draw_boxes(ax: Axes, data: Sequence[np.ndarray], positions: Sequence[float], colour: str,
               width: float = 0.6) -> None:
    """Draw one box per array of ``data`` at ``positions``, filled with ``colour`` (empty arrays skipped)."""
    keep = [(np.asarray(d, float), p) for d, p in zip(data, positions) if len(d)]
    if not keep:
        return
    ax.boxplot([d for d, _ in keep], positions=[p for _, p in keep], widths=width, whis=WHISKER_IQR,
               patch_artist=True, manage_ticks=False,
               boxprops=dict(facecolor=colour, edgecolor="black", alpha=0.85),
               medianprops=dict(color="black", linewidth=1.5),
               whiskerprops=dict(color="black"), capprops=dict(color="black"),
               flierprops=dict(marker="D", markerfacecolor="black", markeredgecolor="black",
                               markersize=3, linestyle="none"))


def honest_vs_byzantine(ax: Axes, values: np.ndarray, honest: np.ndarray, centre: float = 0.0,
                        width: float = 0.35) -> None:
    """Two boxes side by side at ``centre``: honest robots (blue, left) and Byzantine robots (red, right);
    a swarm without Byzantine robots gets one blue box at ``centre``."""
    values, honest = np.asarray(values, float), np.asarray(honest, bool)
    if honest.all():
        draw_boxes(ax, [values], [centre], HONEST, width)
        return
    draw_boxes(ax, [values[honest]], [centre - width / 2 - 0.02], HONEST, width)
    draw_boxes(ax, [values[~honest]], [centre + width / 2 + 0.02], BYZANTINE, width)


def legend_handles(labels: dict[str, str] | None = None) -> list[Patch]:
    """Legend patches for the two colours (labels default to honest / Byzantine)."""
    labels = labels or {HONEST: "honest", BYZANTINE: "Byzantine"}
    return [Patch(facecolor=c, edgecolor="black", label=lab) for c, lab in labels.items()]
