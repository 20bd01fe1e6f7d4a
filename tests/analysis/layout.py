"""Checks that a figure's labels are readable: every text inside the figure, no two texts overlapping,
and no text inside a panel crossed by a box, whisker or bar (matplotlib's renderer gives the extents)."""
from __future__ import annotations

from matplotlib.figure import Figure
from matplotlib.text import Text


def _texts(fig: Figure) -> list[Text]:
    out: list[Text] = []
    if fig._suptitle is not None:
        out.append(fig._suptitle)
    for leg in fig.legends:
        out += leg.get_texts()
    out += fig.texts
    for ax in fig.axes:
        out += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        out += [t.label1 for t in ax.xaxis._update_ticks() + ax.yaxis._update_ticks()]
        out += ax.texts
        if ax.get_legend() is not None:
            out += ax.get_legend().get_texts()
    return [t for t in out if t.get_visible() and t.get_text().strip()]


def _data_artists(ax):
    """Boxes, bars and lines drawn in data coordinates (not reference lines spanning the axes)."""
    return list(ax.patches) + [ln for ln in ax.lines if ln.get_transform() == ax.transData]


def problems(fig: Figure, pad: float = 1.0) -> list[str]:
    """What is wrong with the figure's texts, as sentences (empty when nothing is)."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    page = fig.bbox
    texts = _texts(fig)
    boxes = [(t, t.get_window_extent(r)) for t in texts]
    out = []
    for t, b in boxes:
        if b.x0 < page.x0 - pad or b.y0 < page.y0 - pad or b.x1 > page.x1 + pad or b.y1 > page.y1 + pad:
            out.append(f"{t.get_text()!r} is cut by the figure's edge")
    for i, (t, b) in enumerate(boxes):
        for u, c in boxes[i + 1:]:
            if t is not u and b.overlaps(c.padded(-pad)):
                out.append(f"{t.get_text()!r} overlaps {u.get_text()!r}")
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            b = leg.get_window_extent(r).padded(-pad)
            if any(a.get_visible() and a.get_window_extent(r).overlaps(b) for a in _data_artists(ax)):
                out.append(f"the legend of {ax.get_title(loc='left')!r} hides part of the data")
        for t in ax.texts:
            if not t.get_visible() or not t.get_text().strip():
                continue
            b = t.get_window_extent(r).padded(-pad)
            for a in _data_artists(ax):
                if a.get_visible() and a.get_window_extent(r).overlaps(b):
                    out.append(f"{t.get_text()!r} is crossed by a {type(a).__name__}")
                    break
    return out
