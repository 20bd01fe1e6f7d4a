"""Browser viewer and replays: watch the real engine run, robot by robot.

The model never runs in the browser.  The server (``server``) steps an ``infomarket.Simulation`` in
Python, one per browser connection (``session``), and streams compact binary frames (``frames``) over a
WebSocket; the page (``static/``) only draws them.  A replay (``recording``) is the same page with the
frames of a finished run embedded in one HTML file, and a movie (``movie``) draws those frames with
matplotlib.  Nothing here writes to the simulation: the viewer is read-only.
"""
from pathlib import Path

from .frames import COLUMNS, HEADER, Frame, decode, encode, scene

#: The page, its script and its style (package data).
STATIC = Path(__file__).with_name("static")
#: Where ``infomarket view`` listens unless told otherwise (on 127.0.0.1).
DEFAULT_PORT = 8765

__all__ = ["COLUMNS", "DEFAULT_PORT", "HEADER", "STATIC", "Frame", "decode", "encode", "scene"]
