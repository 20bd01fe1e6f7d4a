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
    blue = np.all(np.abs(rgb - (0x2F, 0x6F, 0xD6)) < 40, axis=-1).sum()
    red = np.all(np.abs(rgb - (0xD6, 0x2F, 0x2F)) < 40, axis=-1).sum()
    assert blue > 24 * 5 and red > 3, (blue, red)


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
