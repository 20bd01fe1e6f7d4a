"""The self-contained HTML replay: everything inside one file, and the frames are the engine's."""
from __future__ import annotations

import base64
import gzip
import json
import re

import numpy as np
import pytest

import infomarket as im
from infomarket.viewer.frames import encode, frame_size
from infomarket.viewer.recording import default_every, record, write_html


@pytest.fixture(scope="module")
def recording(fig2b):
    return record(fig2b, 3, steps=205, every=10)


def payload(page: str) -> dict:
    m = re.search(r'<script id="infomarket-replay" type="application/json">(.*?)</script>', page, re.S)
    assert m, "the replay data is embedded"
    return json.loads(m.group(1))


def test_recording_keeps_a_frame_every_k_steps_and_the_last(recording, fig2b):
    steps = [recording.frame(k).step for k in range(len(recording.frames))]
    assert steps == list(range(0, 201, 10)) + [205]
    ref = im.Simulation(fig2b, 3)
    ref.step(205)
    assert recording.frames[-1] == encode(ref)
    assert default_every(15000) == 10 and default_every(10) == 1
    assert default_every(15000, robots=1000) == 31  # under 500 frames of 48 kB each


def test_page_is_self_contained_and_holds_the_run(recording, tmp_path):
    path = write_html(recording, tmp_path / "run.html")
    page = path.read_text()
    assert not re.search(r'\b(src|href)="(?!data:)', page), "nothing is loaded from elsewhere"
    assert "static/viewer" not in page and "<style>" in page
    assert "<title>infomarket replay: fig2B, seed 3</title>" in page
    data = payload(page)
    frames = gzip.decompress(base64.b64decode(data["frames"]))
    assert data["frame_count"] == len(recording.frames) == len(frames) // frame_size(25)
    assert frames == b"".join(recording.frames)
    events = np.frombuffer(gzip.decompress(base64.b64decode(data["events"])), "<i4")
    assert len(events) == 5 * data["event_count"] and data["event_count"] == len(recording.events["step"])
    assert data["scene"]["name"] == "fig2B" and data["every"] == 10
    assert not list(tmp_path.glob("*.part"))


def test_nothing_in_the_data_can_close_the_script_tag(fig2b, tmp_path):
    # names are validated (a safe charset, issue 21); the page must stay safe for any text all the same
    cfg = fig2b.model_copy(update={"name": "evil</script><b>", "description": "<!-- x"})
    page = write_html(record(cfg, 1, steps=5, every=5), tmp_path / "x.html").read_text()
    assert "evil</script>" not in page and "<b>" not in page.split("<body>")[1].split("<script")[0]
    assert payload(page)["scene"]["name"] == "evil</script><b>"
