"""The local web server behind ``infomarket view``: the page over HTTP, frames over a WebSocket.

Routes: ``/`` the page, ``/static/*`` its script and style, ``/api/info`` what is being served (JSON),
``/ws`` one WebSocket per page.  Each WebSocket owns a ``Session``; its commands are in
``session``'s docstring.  The server answers with JSON text messages (``scene``, ``status``, ``robot``,
``error``) and binary frames (``frames``).

Pacing: while playing, a frame goes out at most ``fps`` times a second and only while fewer than
``MAX_IN_FLIGHT`` frames wait for the page's ``ack``, so a slow page or a slow SSH tunnel gets fewer
frames instead of a growing backlog, and pause stays instant.  Stepping runs in a worker thread
(``asyncio.to_thread``), so the server keeps answering other pages meanwhile.

Stopping: Ctrl-C or SIGTERM stop it, closing every page's socket first; so does closing the last page
(after ``idle_grace`` seconds without a new one, so a reload does not stop it) unless
``keep_running``.  It binds 127.0.0.1 only: from another machine, forward the port (docs/viewer.md).

Other web pages: a request whose ``Host`` is not a loopback name (``localhost``, ``127.0.0.1``, ``[::1]``,
any port, so forwarded ports work) or the address it was started on is refused (403), so a page that
re-binds its own domain name to 127.0.0.1 (DNS rebinding) cannot read it; and a WebSocket whose
``Origin`` is not the viewer's own page (``http://`` + the request's ``Host``) is refused, so another
site open in the browser cannot drive it.  Clients that send no ``Origin`` (scripts, not browsers) are let in.
"""
from __future__ import annotations

import asyncio
import contextlib
import errno
import signal
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from aiohttp import WSCloseCode, WSMsgType, web

from .._version import __version__
from ..config.schema import Experiment
from ..errors import InfomarketError, InternalError
from . import DEFAULT_PORT, STATIC
from .session import CommandError, Session, parse_command

DEFAULT_FPS = 60
MAX_IN_FLIGHT = 3


@dataclass
class ServerState:
    """What the app shares between requests: the experiment and the open sockets."""

    config: Experiment
    seed: int | None
    fps: float
    idle_grace: float | None
    stop: asyncio.Event | None = None
    sockets: set = field(default_factory=set)
    served: int = 0
    on_idle: Callable[[], None] | None = None


STATE = web.AppKey("infomarket_viewer", ServerState)
HOSTS = web.AppKey("infomarket_viewer_hosts", frozenset)

#: Host names the viewer answers to wherever it was started (it binds loopback only).
LOOPBACK = frozenset({"localhost", "127.0.0.1", "[::1]", "::1"})


def _host_name(host: str) -> str:
    """``localhost`` from ``localhost:8765``, ``[::1]`` from ``[::1]:8765``; lower case."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[:host.find("]") + 1] if "]" in host else host
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


@web.middleware
async def _same_origin_only(request: web.Request, handler):
    """Refuse requests that another site could have made through the user's browser (module docstring)."""
    host = request.headers.get("Host", "")
    if _host_name(host) not in request.app[HOSTS]:
        return web.Response(status=403, text="infomarket viewer: this address is not the viewer's own "
                                             "(open it as http://localhost:PORT/)\n")
    origin = request.headers.get("Origin")
    if request.path == "/ws" and origin is not None and origin.lower() != f"http://{host.strip().lower()}":
        return web.Response(status=403, text="infomarket viewer: WebSocket from another site refused\n")
    return await handler(request)


class _Connection:
    """One page: its session, and the loop that interleaves its commands with paced frames."""

    def __init__(self, ws: web.WebSocketResponse, session: Session, fps: float):
        self.ws, self.session = ws, session
        self.period = 1.0 / fps
        self.in_flight = 0
        self.last_sent = 0.0

    async def run(self) -> None:
        await self._send_scene()
        receive = asyncio.ensure_future(self.ws.receive())
        try:
            while True:
                done, _ = await asyncio.wait({receive}, timeout=self._until_next_frame())
                if receive not in done:
                    await self._send_frame(self.session.speed)
                    continue
                msg = receive.result()
                if msg.type in (WSMsgType.CLOSE, WSMsgType.CLOSING, WSMsgType.CLOSED, WSMsgType.ERROR):
                    return
                if msg.type == WSMsgType.TEXT:
                    await self._handle(msg.data)
                receive = asyncio.ensure_future(self.ws.receive())
        finally:
            receive.cancel()

    def _until_next_frame(self) -> float | None:
        if not self.session.playing or self.in_flight >= MAX_IN_FLIGHT:
            return None
        return max(0.0, self.last_sent + self.period - time.monotonic())

    async def _send_scene(self) -> None:
        s = self.session
        await self.ws.send_json(s.scene())
        await self.ws.send_json(s.status())
        await self.ws.send_bytes(s.frame())
        self.in_flight += 1

    async def _send_frame(self, steps: int) -> None:
        frame, detail = await asyncio.to_thread(self.session.advance, steps)
        self.last_sent = time.monotonic()
        await self.ws.send_bytes(frame)
        self.in_flight += 1
        if detail is not None:
            await self.ws.send_json(detail)

    async def _handle(self, text: str) -> None:
        s = self.session
        try:
            cmd = parse_command(text, s.robots)
        except CommandError as exc:
            await self.ws.send_json({"type": "error", "message": str(exc)})
            return
        if cmd.name == "ack":
            self.in_flight = max(0, self.in_flight - 1)
            return
        if cmd.name in ("play", "pause"):
            s.playing = cmd.name == "play"
        elif cmd.name == "speed":
            s.speed = cmd.value
        elif cmd.name == "step":
            s.playing = False
            await self._send_frame(cmd.value)
        elif cmd.name == "select":
            s.selected = cmd.value
            if cmd.value is not None:
                await self.ws.send_json(s.detail())
        elif cmd.name == "restart":
            await asyncio.to_thread(s.restart, cmd.value)
            self.in_flight = 0
            await self._send_scene()
            if s.selected is not None:
                await self.ws.send_json(s.detail())
        await self.ws.send_json(s.status())


async def _page(request: web.Request) -> web.FileResponse:
    return web.FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-cache"})


async def _info(request: web.Request) -> web.Response:
    st = request.app[STATE]
    cfg = st.config
    return web.json_response({
        "version": __version__, "experiment": cfg.name, "description": cfg.description,
        "robots": cfg.swarm.robots, "seed": st.seed if st.seed is not None else cfg.seed,
        "pages": len(st.sockets), "pages_served": st.served, "fps": st.fps})


async def _websocket(request: web.Request) -> web.WebSocketResponse:
    st = request.app[STATE]
    # No permessage-deflate: float32 columns barely compress, compressing big frames costs a worker
    # thread per frame, and aiohttp may then write a data frame after a concurrent close frame.
    ws = web.WebSocketResponse(heartbeat=30.0, max_msg_size=1 << 16, compress=False)
    await ws.prepare(request)
    seed = request.query.get("seed")
    if seed is None:
        seed = st.seed if st.seed is not None else st.config.seed
    st.sockets.add(ws)
    st.served += 1
    try:
        try:
            session = await asyncio.to_thread(Session, st.config, int(seed))
        except ValueError:
            await ws.send_json({"type": "error", "message": f"seed must be a non-negative integer, got {seed!r}"})
            return ws
        await _Connection(ws, session, st.fps).run()
    except (ConnectionResetError, asyncio.CancelledError):
        pass  # the page went away mid-send, or the server is stopping
    except InfomarketError as exc:  # e.g. the engine reported an unrecoverable state: tell the page
        with contextlib.suppress(Exception):
            await ws.send_json({"type": "error", "message": str(exc)})
    finally:
        st.sockets.discard(ws)
        if not st.sockets:
            _maybe_idle(request.app)
        with contextlib.suppress(Exception):
            await ws.close()
    return ws


def _maybe_idle(app: web.Application) -> None:
    """Stop the server ``idle_grace`` seconds after the last page closed, unless one came back."""
    st = app[STATE]
    if st.idle_grace is None or st.stop is None:
        return

    def check() -> None:
        if not st.sockets and not st.stop.is_set():
            if st.on_idle:
                st.on_idle()
            st.stop.set()

    asyncio.get_running_loop().call_later(st.idle_grace, check)


async def _close_sockets(app: web.Application) -> None:
    for ws in list(app[STATE].sockets):
        await ws.close(code=WSCloseCode.GOING_AWAY, message=b"server stopping")


def create_app(config: Experiment, seed: int | None = None, *, fps: float = DEFAULT_FPS,
               idle_grace: float | None = None, host: str = "127.0.0.1") -> web.Application:
    """The viewer as an aiohttp application (tests serve it with aiohttp's test server).  ``host``, the
    address it is served on, is a ``Host`` it answers to besides the loopback names."""
    app = web.Application(middlewares=[_same_origin_only])
    app[STATE] = ServerState(config, seed, fps, idle_grace)
    app[HOSTS] = LOOPBACK | {_host_name(host), _host_name(f"[{host}]") if ":" in host else host.lower()}
    app.router.add_get("/", _page)
    app.router.add_get("/api/info", _info)
    app.router.add_get("/ws", _websocket)
    app.router.add_static("/static", STATIC)
    app.on_shutdown.append(_close_sockets)
    return app


def bind(host: str, port: int) -> tuple[socket.socket, bool]:
    """A listening socket on ``port``, or on a free port if that one is taken; and whether it moved."""
    for p in (port, 0) if port else (0,):
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, p))
        except OSError as exc:
            sock.close()
            if p == 0 or exc.errno not in (errno.EADDRINUSE, errno.EACCES):
                raise
            continue
        sock.listen(128)
        return sock, bool(port) and p != port
    raise InternalError("bind: the last try (port 0) either binds or raises")  # unreachable


async def serve(config: Experiment, seed: int | None = None, *, port: int = DEFAULT_PORT,
                host: str = "127.0.0.1", keep_running: bool = False, idle_grace: float = 5.0,
                fps: float = DEFAULT_FPS, say: Callable[[str], None] = print,
                announce: Callable[[str], None] | None = None) -> None:
    """Serve until Ctrl-C, SIGTERM, or (unless ``keep_running``) the last page closes.  ``say`` tells what
    happens; ``announce`` (default: ``say``) gets the one line with the address to open, as its last word."""
    announce = announce or say
    app = create_app(config, seed, fps=fps, idle_grace=None if keep_running else idle_grace, host=host)
    st = app[STATE]
    st.stop = asyncio.Event()
    st.on_idle = lambda: say("the last page was closed; stopping (--keep-running keeps serving)")
    sock, moved = bind(host, port)
    actual = sock.getsockname()[1]
    if moved:
        say(f"port {port} is busy; using {actual} instead")
    loop = asyncio.get_running_loop()
    with contextlib.suppress(NotImplementedError):  # before the address is printed: no window without it
        loop.add_signal_handler(signal.SIGTERM, st.stop.set)
    runner = web.AppRunner(app, access_log=None, shutdown_timeout=2.0)
    await runner.setup()
    try:
        await web.SockSite(runner, sock).start()
        announce(f"infomarket viewer: {config.name}, {config.swarm.robots} robots; open http://{host}:{actual}/")
        say("press Ctrl-C to stop")
        await st.stop.wait()
    finally:
        with contextlib.suppress(NotImplementedError):
            loop.remove_signal_handler(signal.SIGTERM)
        await runner.cleanup()
        sock.close()
