"""Movies of a recording: GIF always, MP4 when an ffmpeg binary is available."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from infomarket.errors import ConfigError
from infomarket.viewer import movie
from infomarket.viewer.recording import record


@pytest.fixture(scope="module")
def recording(fig2b):
    return record(fig2b, 1, steps=120, every=10)


def test_gif_has_one_picture_per_frame_with_the_swarm_drawn(recording, tmp_path):
    path = movie.write_movie(recording, tmp_path / "run.gif")
    with Image.open(path) as im:
        assert im.n_frames == len(recording.frames) == 13
        assert im.size[0] == movie.WIDTH_PX[".gif"]
        im.seek(im.n_frames - 1)
        rgb = np.asarray(im.convert("RGB")).astype(int)
    blue = np.all(np.abs(rgb - (0x00, 0x72, 0xB2)) < 40, axis=-1).sum()
    orange = np.all(np.abs(rgb - (0xE6, 0x9F, 0x00)) < 40, axis=-1).sum()
    assert blue > 24 * 5 and orange > 3, (blue, orange)


def _luminance(hex_colour: str) -> float:
    """WCAG 2 relative luminance of an sRGB colour."""
    channels = [int(hex_colour[i:i + 2], 16) / 255 for i in (1, 3, 5)]
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in channels]
    return 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]


def test_honest_and_byzantine_fills_differ_in_lightness_not_only_in_hue():
    """Issue 21: the red Byzantine was hard to spot at 720 x 428: blue #2f6fd6 and red #d62f2f have the same
    luminance (contrast ratio 1.01), so without full colour vision (or in grey) they look alike.  Blue
    #0072b2 (L = 0.152) and orange #e69f00 (L = 0.416), by hand: ratio (0.416 + 0.05) / (0.152 + 0.05) = 2.3."""
    hi, lo = sorted((_luminance(movie.HONEST), _luminance(movie.BYZANTINE)), reverse=True)
    assert (hi + 0.05) / (lo + 0.05) >= 2.0


def test_the_movie_has_a_legend_and_frames_each_byzantine(recording, tmp_path):
    path = movie.write_movie(recording, tmp_path / "run.gif")
    with Image.open(path) as im:
        im.seek(im.n_frames - 1)
        rgb = np.asarray(im.convert("RGB")).astype(int)
    height, width, _ = rgb.shape
    arena_px = 2 * round(width * 600 / 1200 / 2)
    top = height - 28 - arena_px  # caption and legend above the arena, the progress bar under it
    assert top >= 40 + 20  # room for a legend row under the 40-pixel caption
    band = rgb[40:top]

    def pixels(colour) -> int:
        return int(np.all(np.abs(band - colour) < 40, axis=-1).sum())

    assert pixels((0x00, 0x72, 0xB2)) > 20 and pixels((0xE6, 0x9F, 0x00)) > 20  # both fills in the legend
    assert int((band.max(axis=-1) < 80).sum()) > 200  # its words (dark text)
    # a black square frame around each Byzantine (honest robots have none)
    last = recording.frame(len(recording.frames) - 1).columns
    scene = recording.scene
    honest = np.array([scene["behaviours"][k]["honest"] for k in scene["kind"]])
    scale = width / 1200

    def dark_in_frame_ring(i: int) -> int:
        cx, cy = last["x"][i] * scale, top + last["y"][i] * scale
        ys, xs = np.mgrid[0:height, 0:width]
        cheb = np.maximum(np.abs(xs - cx), np.abs(ys - cy))  # square rings around the robot
        ring = (cheb >= 6.5) & (cheb <= 10.5) & (ys >= top)
        return int((rgb[ring].max(axis=-1) < 80).sum())

    assert all(dark_in_frame_ring(i) > 12 for i in np.flatnonzero(~honest))
    assert np.median([dark_in_frame_ring(i) for i in np.flatnonzero(honest)]) < 3


def test_frames_are_thinned_evenly_to_the_cap():
    assert movie.pick_frames(10, 20).tolist() == list(range(10))
    picked = movie.pick_frames(1501, 200)
    assert len(picked) == 200 and picked[0] == 0 and picked[-1] == 1500


@pytest.mark.skipif(movie.ffmpeg_path() is None, reason="no ffmpeg binary (imageio-ffmpeg not installed)")
def test_mp4_is_written_with_ffmpeg(recording, tmp_path):
    path = movie.write_movie(recording, tmp_path / "run.mp4")
    head = path.read_bytes()[:64]
    assert b"ftyp" in head and path.stat().st_size > 5_000


def test_mp4_without_ffmpeg_suggests_a_gif(monkeypatch, tmp_path):
    monkeypatch.setattr(movie, "ffmpeg_path", lambda: None)
    with pytest.raises(ConfigError, match=r"needs ffmpeg.*\.gif"):
        movie.check_movie_path(tmp_path / "run.mp4")


@pytest.mark.parametrize("name", ["run.avi", "run"])
def test_other_formats_are_refused(tmp_path, name):
    with pytest.raises(ConfigError, match=r"\.mp4 or \.gif"):
        movie.check_movie_path(tmp_path / name)


def _chain_recording():
    """The partition story of test_chain_view at step 5 (robot 0 on a fork, branch 1; robots 1-3 on the
    canonical branch), with robot 3's branch marked dropped by hand: one frame."""
    from infomarket.ledger.blocklog import DROPPED
    from infomarket.viewer import frames as fr
    from infomarket.viewer.recording import Recording

    from .test_chain_view import _partitioned

    sim = _partitioned()
    data = bytearray(fr.encode(sim))
    header, columns = fr.layout(chain=True)
    offset = 8 * len(header) + sum(4 * np.dtype(t).itemsize for c, t in columns if c != "branch")  # 4 robots
    assert [c for c, _ in columns][-1] == "branch" and data[offset:offset + 4] == bytes([1, 0, 0, 0])
    data[offset + 3] = DROPPED
    return Recording(fr.scene(sim), [bytes(data)], fr.event_columns(sim), 1)


def test_a_chain_movie_rings_each_robot_off_the_canonical_branch(tmp_path):
    """Robot 0 (on branch 1) gets a ring in the first branch colour, robot 3 (dropped) a grey one; robots
    1 and 2, on the canonical branch, none; the legend names both rings."""
    rec = _chain_recording()
    path = movie.write_movie(rec, tmp_path / "chain.gif")
    with Image.open(path) as im:
        rgb = np.asarray(im.convert("RGB")).astype(int)
    height, width, _ = rgb.shape
    arena_px = 2 * round(width * 600 / 1200 / 2)
    top = height - 28 - arena_px
    scale = width / 1200
    ys, xs = np.mgrid[0:height, 0:width]
    xy = rec.frame(0).columns

    def near(colour, i, lo, hi, tol=30) -> int:
        """Pixels of ``colour`` between ``lo`` and ``hi`` pixels from robot i's centre."""
        d = np.hypot(xs - xy["x"][i] * scale, ys - (top + xy["y"][i] * scale))
        return int((np.all(np.abs(rgb - colour) < tol, axis=-1) & (d >= lo) & (d <= hi)).sum())

    purple, grey = (0x94, 0x67, 0xBD), (0x66, 0x66, 0x66)
    ring = (8 * scale + 1.5, 8 * scale + 4.5)  # 3 pixels out from the disc (radius 8), 2 points wide
    assert near(purple, 0, *ring) > 15
    assert near(grey, 3, *ring, tol=12) > 8  # dashed: about half a ring
    for i in (1, 2):
        assert near(purple, i, *ring) == 0 and near(grey, i, *ring, tol=12) == 0
    legend = rgb[40:top]
    assert np.all(np.abs(legend - purple) < 30, axis=-1).sum() > 15  # the ring's legend marker


def test_a_chain_movies_caption_says_the_chain_line():
    """As the page's chain status line: height, forks and reorganisations from the header; the robots off
    the canonical branch and how many other branches they are on (a dropped branch is not one)."""
    from infomarket.ledger.blocklog import DROPPED

    header = {"chain_height": 12.0, "chain_forks": 3.0, "chain_reorgs": 1.0}
    assert movie.chain_status(header, np.array([0, 1, 1, 2, DROPPED], np.uint8)) == (
        "chain: height 12, 3 forks, 1 reorganisations; 4 robots off the canonical branch, on 2 others")
    assert movie.chain_status(header, np.array([0, DROPPED], np.uint8)).endswith("; 1 robot off the canonical branch")


def test_a_caption_too_long_for_the_picture_is_set_smaller_to_fit(recording):
    picture = movie.ArenaPicture(recording.scene, 720, 120)
    last = recording.frame(len(recording.frames) - 1)
    picture.draw(last)
    normal = picture.caption.get_fontsize()
    picture.draw(last, seed=2**63 - 1)  # 19 digits: the caption would run past the right edge at 11 pt
    box = picture.caption.get_window_extent(picture.fig.canvas.get_renderer())
    assert "seed 9223372036854775807:" in picture.caption.get_text()
    assert picture.caption.get_fontsize() < normal and box.x1 <= 720
