"""Fixtures for the viewer: the Fig. 2B setup, a 1 000-robot swarm, and a viewer server in a thread."""
from __future__ import annotations

import asyncio
import threading

import pytest
from aiohttp import web

import infomarket as im
from infomarket.viewer.server import bind, create_app

from ..procs import HANG


@pytest.fixture(scope="session")
def fig2b():
    return im.load_experiment("fig2B")


def thousand_robots() -> im.Experiment:
    """1 000 robots (999 naive, one saboteur: the same compiled kernel as Fig. 2B) in an arena scaled
    up 2.5 times, so the density stays near the paper's."""
    return im.Experiment.model_validate({
        "name": "thousand", "steps": 100_000,
        "arena": {"width": 3000, "height": 1500},
        "food": {"x": 500, "y": 750}, "nest": {"x": 2500, "y": 750},
        "swarm": {"robots": 1000, "groups": [{"behaviour": "naive", "count": 999},
                                             {"behaviour": "saboteur", "count": 1}]},
    })


class ServerThread:
    """The viewer app served on a free 127.0.0.1 port from its own event loop in a daemon thread."""

    def __init__(self, config, seed=None, **kw):
        self.loop = asyncio.new_event_loop()
        self.app = create_app(config, seed, **kw)
        self.sock, _ = bind("127.0.0.1", 0)
        self.url = f"http://127.0.0.1:{self.sock.getsockname()[1]}/"
        self.runner = web.AppRunner(self.app, access_log=None, shutdown_timeout=1.0)
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self._call(self._start())

    def _call(self, coro, timeout=HANG):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    async def _start(self):
        await self.runner.setup()
        await web.SockSite(self.runner, self.sock).start()

    def stop(self):
        self._call(self.runner.cleanup())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(10)
        self.sock.close()


@pytest.fixture(scope="module")
def server_2b(fig2b):
    srv = ServerThread(fig2b, seed=2)
    yield srv
    srv.stop()
