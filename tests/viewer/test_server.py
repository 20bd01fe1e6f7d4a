"""The viewer server's API: HTTP routes, the WebSocket protocol, one simulation per page, stopping."""
from __future__ import annotations

import asyncio
import json
import signal
import socket
import subprocess

import aiohttp
import numpy as np
import pytest
from aiohttp import WSMsgType
from aiohttp.test_utils import TestClient, TestServer

import infomarket as im
from infomarket.viewer.frames import decode, encode
from infomarket.viewer.server import MAX_IN_FLIGHT, bind, create_app, serve

from ..procs import HANG

N = 25


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, HANG))


async def client_for(config, seed=2, **kw) -> TestClient:
    client = TestClient(TestServer(create_app(config, seed, **kw)))
    await client.start_server()
    return client


async def recv(ws, timeout=HANG):
    """('json', dict) or ('frame', Frame)."""
    msg = await ws.receive(timeout=timeout)
    if msg.type == WSMsgType.BINARY:
        return "frame", decode(msg.data, N)
    assert msg.type == WSMsgType.TEXT, msg
    return "json", json.loads(msg.data)


async def expect(ws, kind, type_=None):
    got, value = await recv(ws)
    assert got == kind, (kind, type_, value)
    if type_ is not None:
        assert value["type"] == type_, value
    return value


async def opened(client, query=""):
    """A page's socket, past its greeting (scene, status, first frame)."""
    ws = await client.ws_connect("/ws" + query)
    scene = await expect(ws, "json", "scene")
    await expect(ws, "json", "status")
    first = await expect(ws, "frame")
    return ws, scene, first


async def step(ws, n):
    await ws.send_json({"cmd": "step", "n": n})
    frame = await expect(ws, "frame")
    status = await expect(ws, "json", "status")
    return frame, status


def test_page_static_files_and_info(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            page = await client.get("/")
            assert page.status == 200
            text = await page.text()
            assert '<canvas id="arena"' in text
            assert text.index('src="static/viewer-draw.js"') < text.index('src="static/viewer.js"')
            for name, kind in (("viewer-draw.js", "javascript"), ("viewer.js", "javascript"), ("viewer.css", "css")):
                r = await client.get(f"/static/{name}")
                assert r.status == 200 and kind in r.headers["Content-Type"]
            info = await (await client.get("/api/info")).json()
            assert info["experiment"] == "fig2B" and info["robots"] == N and info["seed"] == 2
            assert (await client.get("/static/nothing.js")).status == 404
        finally:
            await client.close()
    run(go())


def test_greeting_describes_the_run_and_frames_come_from_the_engine(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            ws, scene, first = await opened(client)
            assert scene["n"] == N and scene["seed"] == 2 and scene["name"] == "fig2B"
            assert [b["name"] for b in scene["behaviours"]] == ["naive", "saboteur"]
            assert scene["kind"].count(1) == 1 and len(scene["bias"]) == N
            assert first.step == 0
            await ws.send_json({"cmd": "step", "n": 37})
            raw = await ws.receive(timeout=HANG)
            assert raw.type == WSMsgType.BINARY
            status = await expect(ws, "json", "status")
            assert status["step"] == 37 and not status["playing"]
            reference = im.Simulation(fig2b, 2)  # the same engine, run here, gives the same bytes
            reference.step(37)
            assert raw.data == encode(reference)
        finally:
            await client.close()
    run(go())


def test_play_streams_frames_speed_apart_and_waits_for_acks(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            ws, _, _ = await opened(client)
            await ws.send_json({"cmd": "speed", "value": 4})
            assert (await expect(ws, "json", "status"))["speed"] == 4
            await ws.send_json({"cmd": "play"})
            assert (await expect(ws, "json", "status"))["playing"]
            steps = [(await expect(ws, "frame")).step for _ in range(MAX_IN_FLIGHT - 1)]
            assert steps == [4 * (k + 1) for k in range(MAX_IN_FLIGHT - 1)]
            with pytest.raises(asyncio.TimeoutError):  # the greeting's frame counts: no credit left
                await ws.receive(timeout=0.4)
            await ws.send_json({"cmd": "ack"})
            assert (await expect(ws, "frame")).step == 4 * MAX_IN_FLIGHT
            await ws.send_json({"cmd": "pause"})
            status = await expect(ws, "json", "status")
            assert not status["playing"]
            for _ in range(MAX_IN_FLIGHT):
                await ws.send_json({"cmd": "ack"})
            with pytest.raises(asyncio.TimeoutError):  # paused: nothing more comes
                await ws.receive(timeout=0.3)
        finally:
            await client.close()
    run(go())


def test_selecting_a_robot_sends_its_details_with_every_frame(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            ws, _, _ = await opened(client)
            await step(ws, 300)
            await ws.send_json({"cmd": "select", "robot": 24})
            detail = await expect(ws, "json", "robot")
            assert detail["id"] == 24 and detail["behaviour"] == "saboteur" and detail["step"] == 300
            assert {"pending", "open_transactions", "events", "state"} <= detail.keys()
            await expect(ws, "json", "status")
            await ws.send_json({"cmd": "step", "n": 5})
            await expect(ws, "frame")
            assert (await expect(ws, "json", "robot"))["step"] == 305
            await expect(ws, "json", "status")
            await ws.send_json({"cmd": "select", "robot": None})
            assert (await expect(ws, "json", "status"))["selected"] is None
        finally:
            await client.close()
    run(go())


def test_restart_gives_a_fresh_swarm_with_the_asked_or_a_new_seed(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            ws, _, _ = await opened(client)
            await step(ws, 50)
            await ws.send_json({"cmd": "restart", "seed": 7})
            scene = await expect(ws, "json", "scene")
            await expect(ws, "json", "status")
            frame = await expect(ws, "frame")
            assert scene["seed"] == 7 and frame.step == 0
            await expect(ws, "json", "status")
            await ws.send_json({"cmd": "restart"})
            assert (await expect(ws, "json", "scene"))["seed"] != 7
        finally:
            await client.close()
    run(go())


@pytest.mark.parametrize("message, needle", [
    ("not json", "not JSON"),
    ('["play"]', "expected an object"),
    ('{"cmd": "fly"}', "unknown command"),
    ('{"cmd": "select", "robot": 25}', "robot must be an integer in [0, 24]"),
    ('{"cmd": "speed", "value": 0}', "value must be an integer"),
    ('{"cmd": "step", "n": true}', "n must be an integer"),
    ('{"cmd": "restart", "seed": -1}', "seed must be an integer"),
])
def test_bad_messages_are_answered_and_the_page_keeps_working(fig2b, message, needle):
    async def go():
        client = await client_for(fig2b)
        try:
            ws, _, _ = await opened(client)
            await ws.send_str(message)
            err = await expect(ws, "json", "error")
            assert needle in err["message"]
            frame, _ = await step(ws, 2)
            assert frame.step == 2
        finally:
            await client.close()
    run(go())


def test_two_pages_never_share_a_simulation(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            (a, _, _), (b, _, _) = await opened(client), await opened(client, "?seed=2")
            fa, _ = await step(a, 40)
            fb, _ = await step(b, 3)
            assert (fa.step, fb.step) == (40, 3)
            await a.send_json({"cmd": "restart", "seed": 11})
            assert (await expect(a, "json", "scene"))["seed"] == 11
            fb2, _ = await step(b, 2)
            ref = im.Simulation(fig2b, 2)
            ref.step(5)  # page B saw none of page A's steps or its restart
            assert fb2.step == 5
            np.testing.assert_array_equal(fb2.columns["x"], ref.world.pos[:, 0].astype(np.float32))
            info = await (await client.get("/api/info")).json()
            assert info["pages"] == 2
        finally:
            await client.close()
    run(go())


def test_seed_in_the_page_address_picks_the_swarm(fig2b):
    async def go():
        client = await client_for(fig2b)
        try:
            _, scene, _ = await opened(client, "?seed=123")
            assert scene["seed"] == 123
            ws = await client.ws_connect("/ws?seed=abc")
            assert "seed must be a non-negative integer" in (await expect(ws, "json", "error"))["message"]
        finally:
            await client.close()
    run(go())


def test_a_busy_port_falls_back_to_a_free_one():
    taken, _ = bind("127.0.0.1", 0)
    port = taken.getsockname()[1]
    try:
        sock, moved = bind("127.0.0.1", port)
        assert moved and sock.getsockname()[1] != port
        sock.close()
    finally:
        taken.close()


def test_server_stops_when_the_last_page_closes(fig2b):
    said: list[str] = []

    async def go():
        task = asyncio.create_task(serve(fig2b, 2, port=0, idle_grace=0.2, say=said.append))
        while not any("open http" in s for s in said):
            await asyncio.sleep(0.05)
        url = next(s for s in said if "open http" in s).split("open ")[1]
        async with aiohttp.ClientSession() as http:
            ws = await http.ws_connect(url + "ws")
            await expect(ws, "json", "scene")
            await ws.close()
        await asyncio.wait_for(task, HANG)

    run(go())
    assert any("last page was closed" in s for s in said)


@pytest.mark.parametrize("sig,ignored", [(signal.SIGINT, False), (signal.SIGTERM, False), (signal.SIGINT, True)],
                         ids=["ctrl-c", "sigterm", "ctrl-c-after-a-parent-ignored-it"])
def test_view_command_prints_the_url_and_stops_cleanly_on_a_signal(sig, ignored, procs):
    """``ignored``: what a script's background job (or a test runner's worker) may hand its children."""
    proc = procs.cli("view", "fig2B", "--port", "0", env={"PYTHONUNBUFFERED": "1"}, ignore_ctrl_c=ignored,
                     stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    url = None
    lines = []
    while url is None:
        line = proc.stdout.readline()  # the address is on stdout (issue 21), progress on stderr
        if not line:
            break
        lines.append(line)
        if "open http://127.0.0.1:" in line:
            url = line.split("open ")[1].strip()
    assert url, "".join(lines)
    host, port = url.removeprefix("http://").rstrip("/").split(":")
    with socket.create_connection((host, int(port)), timeout=HANG):
        pass  # it listens, on loopback
    proc.send_signal(sig)
    rest = proc.communicate(timeout=HANG)[1]
    assert proc.returncode == 0, rest
    assert "viewer stopped" in rest and "Traceback" not in rest
    assert procs.leftovers(proc) == []


def test_frames_go_uncompressed_even_when_the_page_offers_deflate(fig2b):
    """Deflate would cost a worker thread per large frame, and aiohttp could then write a data frame
    after a concurrent close frame (browsers report 'Data frame received after close')."""
    async def go():
        client = await client_for(fig2b)
        try:
            ws = await client.ws_connect("/ws", compress=15)
            assert ws.compress == 0
            await expect(ws, "json", "scene")
        finally:
            await client.close()
    run(go())
