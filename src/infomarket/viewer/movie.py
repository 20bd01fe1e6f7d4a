"""Render a recording as a movie, like the paper's Movie S1 (``infomarket replay --movie``).

Same picture as the page: discs coloured by behaviour (honest blue, Byzantine orange: colour-blind-safe
colours of Okabe and Ito, told apart in grey too), each Byzantine also framed by a black square (a shape,
not only a colour, at a movie's small size), outlined by the last site visited, a white heading line, a dark
dot for a carried item; with the chain model, a ring in its branch's colour around each robot off the
canonical branch (grey dashed: its branch was dropped) and the chain's line; a caption with the items
collected, a legend, and a progress bar under the arena.  ``.gif`` uses matplotlib's Pillow writer and always works;
``.mp4`` needs an ffmpeg binary, found on PATH or in the ``imageio-ffmpeg`` wheel.
"""
from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import ConfigError
from ..ledger.blocklog import DROPPED
from .frames import CARRYING, LAST_FOOD, LAST_NEST, Frame
from .recording import Recording

#: Okabe-Ito blue and orange: distinct with every colour-vision deficiency and in luminance (grey prints).
HONEST, BYZANTINE = "#0072b2", "#e69f00"
BYZANTINE_FRAME = "#000000"
SITE_COLOURS = {"food": "#2ca02c", "nest": "#e8b100"}
NO_SITE = "#666666"
#: The chain model's branch colours, in turn for branches 1, 2, ...: the page's (viewer-draw.js BRANCH) without
#: its orange, which a ring around the movie's orange Byzantine discs would hide.
BRANCH = ("#9467bd", "#17becf", "#8c564b", "#e377c2", "#bcbd22")
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
    if path.parent.exists() and not path.parent.is_dir():
        raise ConfigError(f"--movie {path}: {path.parent} is not a folder; give a file name in an existing folder")
    if not path.parent.is_dir():
        raise ConfigError(f"--movie {path}: folder {path.parent} does not exist")
    return path


def pick_frames(count: int, most: int) -> np.ndarray:
    """Indices of at most ``most`` frames spread evenly over ``count``, first and last included."""
    return np.unique(np.linspace(0, count - 1, min(count, most)).round().astype(int))


class ArenaPicture:
    """The movie's picture of one scene (a frames.scene dict): a matplotlib figure whose artists ``draw``
    moves to a frame, ``width_px`` wide.  The movie grabs it frame by frame; the RL environments'
    ``render()`` reads it as an RGB array (``rgb``)."""

    def __init__(self, s: dict, width_px: int, total_steps: int, dpi: int = 100):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.collections import EllipseCollection, LineCollection
        from matplotlib.figure import Figure
        from matplotlib.patches import Circle, Rectangle

        self.scene, self.total_steps = s, max(int(total_steps), 1)
        W, H = s["arena"]["width"], s["arena"]["height"]
        self.chain = s.get("chain") is not None
        arena_px = 2 * round(width_px * H / W / 2)
        caption_px, legend_px, bar_px = (58, 44, 28) if self.chain else (40, 26, 28)
        height_px = arena_px + caption_px + legend_px + bar_px
        self.fig = fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, facecolor="white")
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
        self.honest = honest = np.array([s["behaviours"][k]["honest"] for k in s["kind"]])
        self.r = r = s["robot"]["radius"]
        n = s["n"]

        def discs(**kw):
            return ax.add_collection(EllipseCollection(np.zeros(0), np.zeros(0), np.zeros(0), units="xy",
                                                       offsets=np.zeros((0, 2)), offset_transform=ax.transData, **kw))

        self.discs = ax.add_collection(EllipseCollection(np.full(n, 2 * r), np.full(n, 2 * r), np.zeros(n), units="xy",
                                                         offsets=np.zeros((n, 2)), offset_transform=ax.transData,
                                                         facecolors=np.where(honest, HONEST, BYZANTINE),
                                                         linewidths=1.3))
        px_per_unit = width_px / W  # a Byzantine's square frame, in points: 1.7 robot diameters wide
        frame_pt = 1.7 * 2 * r * px_per_unit * 72 / dpi
        self.frames = ax.scatter(np.zeros((~honest).sum()), np.zeros((~honest).sum()), s=frame_pt ** 2, marker="s",
                                 facecolors="none", edgecolors=BYZANTINE_FRAME, linewidths=1.4, zorder=4)
        self.headings = ax.add_collection(LineCollection([], colors="white", linewidths=1.2))
        self.carried = ax.scatter([], [], s=6, c="#222", zorder=5)
        self.collisions = bool(s["robot"].get("collisions"))
        self.rings = discs(facecolors="none", edgecolors=CONTACT, linewidths=1.0) if self.collisions else None
        # the chain model: as on the page, a ring 3 pixels out from the disc, in the robot's branch colour
        self.ring_d = 2 * (r + 3 / px_per_unit)
        self.branch_rings = discs(facecolors="none", linewidths=2.0, zorder=3) if self.chain else None
        self.dropped_rings = discs(facecolors="none", edgecolors=NO_SITE, linewidths=1.5, linestyles=(0, (2, 2)),
                                   zorder=3) if self.chain else None
        self.caption = fig.text(0.01, 1 - 0.5 * 40 / height_px, "", va="center", fontsize=11)
        self.chain_text = fig.text(0.01, 1 - 46 / height_px, "", va="center", fontsize=9) if self.chain else None
        _legend(fig, (1 - (caption_px + legend_px) / height_px, legend_px / height_px), self.collisions,
                byzantines=bool((~honest).any()), chain=self.chain)
        bar_ax = fig.add_axes((0.01, 0.2 * bar_px / height_px, 0.98, 0.6 * bar_px / height_px))
        bar_ax.set_xlim(0, 1)
        bar_ax.set_ylim(0, 1)
        bar_ax.set_axis_off()
        bar_ax.add_patch(Rectangle((0, 0), 1, 1, facecolor="#e6e6e6", edgecolor="none"))
        self.bar = bar_ax.add_patch(Rectangle((0, 0), 0, 1, facecolor="#9db4d8", edgecolor="none"))
        self.bar_text = bar_ax.text(0.5, 0.5, "", ha="center", va="center", fontsize=9, color="#000")
        self.groups = ", ".join(f"{s['kind'].count(k)} {b['name']}" for k, b in enumerate(s["behaviours"]))

    def draw(self, f: Frame, seed: int | None = None) -> None:
        """Move every artist to frame ``f``; ``seed``: the run's, when it is not the scene's (an RL
        environment draws each episode, a new seed, on one picture)."""
        s, r, honest, c = self.scene, self.r, self.honest, f.columns
        xy = np.c_[c["x"], c["y"]]
        a = np.radians(c["heading"].astype(np.float64))
        self.discs.set_offsets(xy)
        self.frames.set_offsets(xy[~honest].reshape(-1, 2))
        self.discs.set_edgecolors(np.where(c["flags"] & LAST_FOOD, SITE_COLOURS["food"],
                                           np.where(c["flags"] & LAST_NEST, SITE_COLOURS["nest"], NO_SITE)))
        self.headings.set_segments(np.stack([xy, xy + r * np.c_[np.cos(a), np.sin(a)]], axis=1))
        self.carried.set_offsets(xy[(c["flags"] & CARRYING) > 0].reshape(-1, 2))
        if self.rings is not None:
            _place(self.rings, xy[in_contact(xy, r)], 2 * r + 3)
        h = f.header
        items = h["items_honest"] + h["items_byzantine"]
        seed = s["seed"] if seed is None else seed
        _fit(self.caption, f"{s['name']} ({self.groups}), seed {seed}: {items:.0f} items collected "
                           f"(honest {h['items_honest']:.0f}, Byzantine {h['items_byzantine']:.0f})", 11)
        if self.chain:
            branch = c["branch"]
            forked = (branch != 0) & (branch != DROPPED)
            _place(self.branch_rings, xy[forked], self.ring_d)
            self.branch_rings.set_edgecolors([branch_colour(b) for b in branch[forked]])
            _place(self.dropped_rings, xy[branch == DROPPED], self.ring_d)
            _fit(self.chain_text, chain_status(h, branch), 9)
        self.bar.set_width(min(f.step / self.total_steps, 1.0))
        self.bar_text.set_text(f"step {f.step} / {self.total_steps}")

    def rgb(self) -> np.ndarray:
        """[height, width, 3] uint8: the picture as drawn now."""
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[..., :3].copy()


def branch_colour(b: int) -> str:
    """A branch's colour, as on the page: ``BRANCH`` in turn for branches 1, 2, ..."""
    return BRANCH[(int(b) - 1) % len(BRANCH)]


def chain_status(header: dict, branch: np.ndarray) -> str:
    """The chain's line, as on the page: canonical height, forks and reorganisations so far, the robots
    off the canonical branch and on how many other branches."""
    off = int((branch != 0).sum())
    others = len(set(branch[(branch != 0) & (branch != DROPPED)].tolist()))
    text = (f"chain: height {header['chain_height']:.0f}, {header['chain_forks']:.0f} forks, "
            f"{header['chain_reorgs']:.0f} reorganisations; {off} robot{'' if off == 1 else 's'} off the canonical "
            "branch")
    return text + (f", on {others} other{'' if others == 1 else 's'}" if others else "")


def _fit(text, value: str, fontsize: float) -> None:
    """Set ``text`` at ``fontsize``, smaller where it would run past the figure's right edge (a long
    seed, a long name)."""
    text.set_text(value)
    text.set_fontsize(fontsize)
    fig = text.get_figure()
    box = text.get_window_extent(fig.canvas.get_renderer())
    room = fig.bbox.width * 0.985 - box.x0
    if box.width > room:
        text.set_fontsize(fontsize * room / box.width)


def _place(rings, xy: np.ndarray, diameter: float) -> None:
    k = len(xy)
    rings.set_offsets(xy.reshape(-1, 2))
    rings.set_widths(np.full(k, diameter))
    rings.set_heights(np.full(k, diameter))
    rings.set_angles(np.zeros(k))


def write_movie(rec: Recording, path: str | Path, *, fps: int | None = None, max_frames: int | None = None,
                on_progress: Callable[[int, int], None] | None = None) -> Path:
    """Draw ``rec`` frame by frame into ``path`` (.gif or .mp4)."""
    from matplotlib import animation, rcParams

    path = check_movie_path(path)
    ext = path.suffix.lower()
    fps = fps or FPS[ext]
    dpi = 100
    picture = ArenaPicture(rec.scene, WIDTH_PX[ext], rec.frame(len(rec.frames) - 1).step, dpi)
    if ext == ".gif":
        writer = animation.PillowWriter(fps=fps)
    else:
        rcParams["animation.ffmpeg_path"] = ffmpeg_path()
        writer = animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
    picks = pick_frames(len(rec.frames), max_frames or MAX_FRAMES[ext])
    tmp = path.with_name(path.stem + ".part" + path.suffix)
    try:  # not ``writer.saving``: on Ctrl-C or an error its exit would still encode every frame grabbed
        writer.setup(picture.fig, str(tmp), dpi)
        for j, k in enumerate(picks):
            picture.draw(rec.frame(int(k)))
            writer.grab_frame()
            if on_progress:
                on_progress(j + 1, len(picks))
        writer.finish()
        tmp.replace(path)
    except BaseException:  # stopped or failed: no half-written movie is left behind, no encoder left running
        _abandon(writer)
        tmp.unlink(missing_ok=True)
        raise
    return path


def _abandon(writer) -> None:
    """Stop a movie writer without encoding what it holds: ffmpeg (a child process) is killed and reaped;
    Pillow's frames are dropped."""
    proc = getattr(writer, "_proc", None)
    if proc is not None and proc.poll() is None:
        proc.kill()
        proc.wait()
    if hasattr(writer, "_frames"):
        writer._frames = []


def _legend(fig, band: tuple[float, float], collisions: bool, byzantines: bool = True, chain: bool = False) -> None:
    """Under the caption: what the fills, the frame, the outlines, the dot and the rings mean (one row; two
    with the chain model's rings)."""
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
    if chain:
        handles += [marker(marker="o", markersize=12, markerfacecolor="none", markeredgecolor=BRANCH[0],
                           markeredgewidth=2),
                    marker(marker="o", markersize=12, markerfacecolor="none", markeredgecolor=NO_SITE,
                           markeredgewidth=1.2)]
        labels += ["off the canonical chain (colour: branch)", "branch dropped"]
    bottom, height = band
    fig.legend(handles, labels, loc="center", bbox_to_anchor=(0, bottom, 1, height),
               ncol=-(-len(labels) // 2) if chain else len(labels),
               frameon=False, fontsize=8.5, handletextpad=0.3, columnspacing=0.6 if chain else 1.0, borderaxespad=0)
