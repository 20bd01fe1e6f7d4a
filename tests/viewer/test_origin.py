"""Issue 21: other web pages in the user's browser can neither read the viewer (DNS rebinding: a foreign
``Host``) nor drive it (a WebSocket from a foreign ``Origin``)."""
from __future__ import annotations

import asyncio

import aiohttp
import pytest
from aiohttp.test_utils import TestClient, TestServer

from infomarket.viewer.server import create_app

from ..procs import HANG


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, 60))


async def client_for(config) -> TestClient:
    client = TestClient(TestServer(create_app(config, 2), host="127.0.0.1"))
    await client.start_server()
    return client


@pytest.mark.parametrize("host", ["evil.example:8765", "evil.example", "127.0.0.1.evil.example", "10.0.0.5:8765"])
def test_a_foreign_host_is_refused(fig2b, host):
    async def go():
        client = await client_for(fig2b)
        try:
            for path in ("/", "/api/info", "/static/viewer.js"):
                r = await client.get(path, headers={"Host": host})
                assert r.status == 403, (path, r.status)
                assert "fig2B" not in await r.text()
            with pytest.raises(aiohttp.WSServerHandshakeError) as err:
                await client.ws_connect("/ws", headers={"Host": host})
            assert err.value.status == 403
        finally:
            await client.close()
    run(go())


@pytest.mark.parametrize("host", ["localhost:9000", "127.0.0.1:8765", "[::1]:8765", "LOCALHOST"])
def test_loopback_hosts_on_any_port_are_served(fig2b, host):
    async def go():
        client = await client_for(fig2b)
        try:
            r = await client.get("/api/info", headers={"Host": host})
            assert r.status == 200 and (await r.json())["experiment"] == "fig2B"
        finally:
            await client.close()
    run(go())


@pytest.mark.parametrize("origin", ["http://evil.example", "null", "https://127.0.0.1:1", "http://localhost:1"])
def test_a_websocket_from_another_origin_is_refused(fig2b, origin):
    async def go():
        client = await client_for(fig2b)
        try:
            with pytest.raises(aiohttp.WSServerHandshakeError) as err:
                await client.ws_connect("/ws", origin=origin)
            assert err.value.status == 403
        finally:
            await client.close()
    run(go())


def test_a_websocket_from_the_viewers_own_page_is_served(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            own = f"http://127.0.0.1:{client.port}"
            ws = await client.ws_connect("/ws", origin=own)
            msg = await ws.receive_json(timeout=HANG)
            assert msg["type"] == "scene" and msg["name"] == "fig2B"
            await ws.close()
        finally:
            await client.close()
    run(go())
