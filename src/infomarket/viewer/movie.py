"""Render a recording as a movie, like the paper's Movie S1 (``infomarket replay --movie``).

Same picture as the page: discs coloured by behaviour (honest blue, Byzantine orange: colour-blind-safe
colours of Okabe and Ito, told apart in grey too), each Byzantine also framed by a black square (a shape,
not only a colour, at a movie's small size), outlined by the last site visited, a white heading line, a dark
dot for a carried item; a caption with the items collected, a legend, and a progress bar under the arena.  ``.gif`` uses matplotlib's Pillow writer and always works;
``.mp4`` needs an ffmpeg binary, found on PATH or in the ``imageio-ffmpeg`` wheel.
"""
from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import ConfigError
from .frames import CARRYING, LAST_FOOD, LAST_NEST
from .recording import Recording

#: Okabe-Ito blue and orange: distinct with every colour-vision deficiency and in luminance (grey prints).
HONEST, BYZANTINE = "#0072b2", "#e69f00"
BYZANTINE_FRAME = "#000000"
SITE_COLOURS = {"food": "#2ca02c", "nest": "#e8b100"}
NO_SITE = "#666666"
#: Per format: frames per second and the most frames kept (a movie of ~15 s; GIFs grow fast).
FPS = {".gif": 15, ".mp4": 30}
MAX_FRAMES = {".gif": 200, ".mp4": 450}
WIDTH_PX = {".gif": 720, ".mp4": 1000}


OBSTACLE = "#5a5a5a"
CONTACT = "#111111"


def draw_obstacles(ax, obstacles: list[dict]) -> None:
    """Obstacles as on the page: rectangles and circles filled, segments as walls."""
    from matplotlib.patches import Circle, Rectangle

    for o in obstacles:
        if o["shape"] == "rect":
            ax.add_patch(Rectangle((o["x0"], o["y0"]), o["x1"] - o["x0"], o["y1"] - o["y0"], facecolor=OBSTACLE,
                                   edgecolor="none"))
        elif o["shape"] == "circle":
            ax.add_patch(Circle((o["x"], o["y"]), o["radius"], facecolor=OBSTACLE, edgecolor="none"))
        else:
            ax.plot([o["x0"], o["x1"]], [o["y0"], o["y1"]], color=OBSTACLE, lw=3, solid_capstyle="round")


def in_contact(xy: np.ndarray, radius: float) -> np.ndarray:
    """[n] bool: robots whose disc touches another's (centres within 2 r + 0.1), as the page rings them."""
    d2 = ((xy[:, None, :].astype(np.float64) - xy[None, :, :]) ** 2).sum(-1)
    np.fill_diagonal(d2, np.inf)
    return (d2 <= (2 * radius + 0.1) ** 2).any(axis=1)


def ffmpeg_path() -> str | None:
    """An ffmpeg binary: on PATH, else the one inside the imageio-ffmpeg wheel, else None."""
    exe = shutil.which("ffmpeg")
    if exe:
        return exe
    try:
        import imageio_ffmpeg
        return imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        return None


def check_movie_path(path: str | Path) -> Path:
    """Refuse, before any work is done, a movie this machine cannot write."""
    path = Path(path)
    if path.suffix.lower() not in FPS:
        raise ConfigError(f"--movie {path}: the name must end in .mp4 or .gif")
    if path.suffix.lower() == ".mp4" and ffmpeg_path() is None:
        raise ConfigError(f"--movie {path}: writing .mp4 needs ffmpeg, and none was found "
                          "(pip install imageio-ffmpeg, or install ffmpeg); a .gif needs nothing more")
    if not path.parent.is_dir():
        raise ConfigError(f"--movie {path}: folder {path.parent} does not exist")
    return path


def pick_frames(count: int, most: int) -> np.ndarray:
    """Indices of at most ``most`` frames spread evenly over ``count``, first and last included."""
    return np.unique(np.linspace(0, count - 1, min(count, most)).round().astype(int))


def write_movie(rec: Recording, path: str | Path, *, fps: int | None = None, max_frames: int | None = None,
                on_progress: Callable[[int, int], None] | None = None) -> Path:
    """Draw ``rec`` frame by frame into ``path`` (.gif or .mp4)."""
    from matplotlib import animation, rcParams
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import EllipseCollection, LineCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Rectangle

    path = check_movie_path(path)
    ext = path.suffix.lower()
    fps = fps or FPS[ext]
    s = rec.scene
    W, H = s["arena"]["width"], s["arena"]["height"]
    dpi = 100
    width_px = WIDTH_PX[ext]
    arena_px = 2 * round(width_px * H / W / 2)
    caption_px, legend_px, bar_px = 40, 26, 28
    height_px = arena_px + caption_px + legend_px + bar_px
    fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, bar_px / height_px, 1, arena_px / height_px))
    ax.set_xlim(0, W)
    ax.set_ylim(H, 0)  # y down, as on the page
    ax.set_axis_off()
    ax.add_patch(Rectangle((0, 0), W, H, facecolor="#f4f4f1", edgecolor="#999", lw=1))
    for site in s["sites"]:
        c = SITE_COLOURS[site["name"]]
        ax.add_patch(Circle((site["x"], site["y"]), site["radius"], facecolor=c, alpha=0.35, edgecolor="none"))
        ax.add_patch(Circle((site["x"], site["y"]), site["radius"], facecolor="none", edgecolor=c, lw=1.5))
    draw_obstacles(ax, s.get("obstacles", []))
    honest = np.array([s["behaviours"][k]["honest"] for k in s["kind"]])
    r = s["robot"]["radius"]
    n = s["n"]
    first = rec.frame(0).columns
    discs = EllipseCollection(np.full(n, 2 * r), np.full(n, 2 * r), np.zeros(n), units="xy",
                              offsets=np.c_[first["x"], first["y"]], offset_transform=ax.transData,
                              facecolors=np.where(honest, HONEST, BYZANTINE), linewidths=1.3)
    ax.add_collection(discs)
    px_per_unit = width_px / W  # a Byzantine's square frame, in points: 1.7 robot diameters wide
    frame_pt = 1.7 * 2 * r * px_per_unit * 72 / dpi
    frames = ax.scatter(first["x"][~honest], first["y"][~honest], s=frame_pt ** 2, marker="s", facecolors="none",
                        edgecolors=BYZANTINE_FRAME, linewidths=1.4, zorder=4)
    headings = LineCollection([], colors="white", linewidths=1.2)
    ax.add_collection(headings)
    carried = ax.scatter([], [], s=6, c="#222", zorder=5)
    collisions = bool(s["robot"].get("collisions"))
    rings = EllipseCollection(np.zeros(0), np.zeros(0), np.zeros(0), units="xy", offsets=np.zeros((0, 2)),
                              offset_transform=ax.transData, facecolors="none", edgecolors=CONTACT,
                              linewidths=1.0)
    if collisions:
        ax.add_collection(rings)
    caption = fig.text(0.01, 1 - 0.5 * caption_px / height_px, "", va="center", fontsize=11)
    _legend(fig, (1 - (caption_px + legend_px) / height_px, legend_px / height_px), collisions,
            byzantines=bool((~honest).any()))
    bar_ax = fig.add_axes((0.01, 0.2 * bar_px / height_px, 0.98, 0.6 * bar_px / height_px))
    bar_ax.set_xlim(0, 1)
    bar_ax.set_ylim(0, 1)
    bar_ax.set_axis_off()
    bar_ax.add_patch(Rectangle((0, 0), 1, 1, facecolor="#e6e6e6", edgecolor="none"))
    bar = bar_ax.add_patch(Rectangle((0, 0), 0, 1, facecolor="#9db4d8", edgecolor="none"))
    bar_text = bar_ax.text(0.5, 0.5, "", ha="center", va="center", fontsize=9, color="#000")

    groups = ", ".join(f"{s['kind'].count(k)} {b['name']}" for k, b in enumerate(s["behaviours"]))
    total_steps = max(rec.frame(len(rec.frames) - 1).step, 1)

    if ext == ".gif":
        writer = animation.PillowWriter(fps=fps)
    else:
        rcParams["animation.ffmpeg_path"] = ffmpeg_path()
        writer = animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
    picks = pick_frames(len(rec.frames), max_frames or MAX_FRAMES[ext])
    tmp = path.with_name(path.stem + ".part" + path.suffix)
    with writer.saving(fig, str(tmp), dpi):
        for j, k in enumerate(picks):
            f = rec.frame(int(k))
            c = f.columns
            xy = np.c_[c["x"], c["y"]]
            a = np.radians(c["heading"].astype(np.float64))
            discs.set_offsets(xy)
            frames.set_offsets(xy[~honest].reshape(-1, 2))
            discs.set_edgecolors(np.where(c["flags"] & LAST_FOOD, SITE_COLOURS["food"],
                                          np.where(c["flags"] & LAST_NEST, SITE_COLOURS["nest"], NO_SITE)))
            headings.set_segments(np.stack([xy, xy + r * np.c_[np.cos(a), np.sin(a)]], axis=1))
            carried.set_offsets(xy[(c["flags"] & CARRYING) > 0].reshape(-1, 2))
            if collisions:
                touching = xy[in_contact(xy, s["robot"]["radius"])]
                rings.set_offsets(touching.reshape(-1, 2))
                rings.set_widths(np.full(len(touching), 2 * r + 3))
                rings.set_heights(np.full(len(touching), 2 * r + 3))
                rings.set_angles(np.zeros(len(touching)))
            h = f.header
            items = h["items_honest"] + h["items_byzantine"]
            caption.set_text(f"{s['name']} ({groups}), seed {s['seed']}: {items:.0f} items collected "
                             f"(honest {h['items_honest']:.0f}, Byzantine {h['items_byzantine']:.0f})")
            bar.set_width(f.step / total_steps)
            bar_text.set_text(f"step {f.step} / {total_steps}")
            writer.grab_frame()
            if on_progress:
                on_progress(j + 1, len(picks))
    tmp.replace(path)
    return path


def _legend(fig, band: tuple[float, float], collisions: bool, byzantines: bool = True) -> None:
    """One row under the caption: what the fills, the frame, the outlines, the dot and the rings mean."""
    from matplotlib.lines import Line2D

    def marker(**kw) -> Line2D:
        return Line2D([], [], linestyle="none", **{"markersize": 9, **kw})

    handles = [marker(marker="o", markerfacecolor=HONEST, markeredgecolor=NO_SITE)]
    labels = ["honest"]
    if byzantines:
        handles.append((marker(marker="o", markerfacecolor=BYZANTINE, markeredgecolor=NO_SITE),
                        marker(marker="s", markersize=13, markerfacecolor="none", markeredgecolor=BYZANTINE_FRAME)))
        labels.append("Byzantine (framed)")
    handles += [marker(marker="o", markerfacecolor="none", markeredgecolor=SITE_COLOURS["food"], markeredgewidth=2),
                marker(marker="o", markerfacecolor="none", markeredgecolor=SITE_COLOURS["nest"], markeredgewidth=2),
                marker(marker="o", markersize=3, markerfacecolor="#222", markeredgecolor="#222")]
    labels += ["last visited food", "last visited nest", "carrying an item"]
    if collisions:
        handles.append(marker(marker="o", markersize=12, markerfacecolor="none", markeredgecolor=CONTACT))
        labels.append("touching")
    bottom, height = band
    fig.legend(handles, labels, loc="center", bbox_to_anchor=(0, bottom, 1, height), ncol=len(labels),
               frameon=False, fontsize=8.5, handletextpad=0.3, columnspacing=1.0, borderaxespad=0)
