"""Frames: one snapshot of the swarm, encoded so the browser reads it without parsing.

A frame is a header of float64 numbers followed by one contiguous little-endian array per robot
attribute (``COLUMNS``), float32 columns first, then uint8 ones, then zero bytes up to a multiple of 8
(``ALIGN``), so every column starts on an aligned offset, in one frame and in a replay's frames laid end
to end, and the page wraps each in a typed-array view (no copy, no JSON): 1 000 robots cost 50 kB.
The live server, the self-contained replay and the movie all draw from these same bytes, so the three
show exactly the same thing.

What does not change during a run (arena, sites, behaviours, odometry biases, the column layout) is
sent once as the *scene*, a JSON object.  Details only the side panel needs (pending purchases, open
transactions, the last events of one robot) travel as JSON on request (``robot_detail``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine import geometry as kernels  # to_world: the robot-frame rotation the engine uses
from ..engine.world import EVENT_NAMES, FOOD, NEST, SITE_NAMES, STATE_NAMES, headings, open_transactions
from ..errors import FormatError
from ..ledger.blocklog import BranchNumbers, chain_views
from ..registry import behaviours

#: The engine's own robot-frame -> world rotation, as plain Python (it also takes arrays of robots).
_to_world = getattr(kernels.to_world, "py_func", kernels.to_world)

#: Header fields, float64 each, in order.
HEADER = ("step", "items_honest", "items_byzantine", "wealth_honest", "wealth_byzantine")

#: Per-robot columns (name, numpy dtype).  food_x/y and nest_x/y are where the robot *believes* each
#: site is: its navigation-table vector taken out of its own frame into the world's.
COLUMNS = (
    ("x", "<f4"), ("y", "<f4"), ("heading", "<f4"), ("wealth", "<f4"), ("items", "<f4"),
    ("food_x", "<f4"), ("food_y", "<f4"), ("nest_x", "<f4"), ("nest_y", "<f4"),
    ("food_age", "<f4"), ("nest_age", "<f4"),
    ("state", "u1"), ("flags", "u1"), ("pending_food", "u1"), ("pending_nest", "u1"),
)

#: With the chain model on (docs/chain-model.md) frames carry more: the canonical height and the forks
#: and reorganisations so far in the header, and per robot its head's height, its lag (canonical height
#: minus its head's) and its branch: 0 when its head is on the canonical branch (however far behind),
#: 1, 2, ... for each other branch (a branch keeps its number from frame to frame while it lasts, when
#: the caller keeps a ``BranchNumbers``, as a session and a recording do), ``DROPPED`` when its branch
#: was dropped.
CHAIN_HEADER = ("chain_height", "chain_forks", "chain_reorgs")
CHAIN_FLOAT_COLUMNS = (("chain_height", "<f4"), ("chain_lag", "<f4"))
CHAIN_BYTE_COLUMNS = (("branch", "u1"),)

#: Bits of the ``flags`` column.
CARRYING, FOOD_VALID, NEST_VALID, LAST_FOOD, LAST_NEST = 1, 2, 4, 8, 16

#: A frame's size is a multiple of this (the widest column type, the float64 header), so that frame k of
#: a replay, at k times the frame size, starts where a Float64Array may begin (viewer-draw.js, ``makeLayout``).
ALIGN = 8

#: How many of a robot's most recent events the side panel lists.
LAST_EVENTS = 8


def layout(chain: bool = False) -> tuple[tuple[str, ...], tuple[tuple[str, str], ...]]:
    """(header, columns) of a frame: ``HEADER``/``COLUMNS``, with the chain's fields when ``chain``
    (float32 columns still first, then the uint8 ones, so every column stays aligned)."""
    if not chain:
        return HEADER, COLUMNS
    floats = tuple(c for c in COLUMNS if c[1] == "<f4") + CHAIN_FLOAT_COLUMNS
    return HEADER + CHAIN_HEADER, floats + tuple(c for c in COLUMNS if c[1] != "<f4") + CHAIN_BYTE_COLUMNS


def chain_on(sim) -> bool:
    """Whether the simulation runs the chain model, so its frames carry the chain's fields."""
    return bool(sim.config.chain.enabled)


def frame_size(n: int, chain: bool = False) -> int:
    """Bytes in one frame of ``n`` robots, padding included."""
    return -(-_payload_size(n, chain) // ALIGN) * ALIGN


def _payload_size(n: int, chain: bool) -> int:
    header, columns = layout(chain)
    return 8 * len(header) + n * sum(np.dtype(t).itemsize for _, t in columns)


def honest_mask(sim) -> np.ndarray:
    """[n] bool: which robots run an honest behaviour."""
    specs = behaviours()
    return np.array([specs[b].honest for b in sim.behaviour_names], dtype=bool)


def scene(sim) -> dict:
    """Everything about a run that stays fixed while it plays, as a JSON-ready dict."""
    cfg = sim.config
    names = list(dict.fromkeys(sim.behaviour_names))
    specs = behaviours()
    return {
        "name": cfg.name,
        "description": cfg.description,
        "seed": sim.seed,
        "seed_text": str(sim.seed),  # exact in the page (a JavaScript number rounds a seed above 2**53)
        "steps": cfg.steps,
        "scheme": cfg.payment.scheme,
        "arena": {"width": cfg.arena.width, "height": cfg.arena.height},
        # every site, food first (a site's "name" is its kind); events name a kind: site_kinds[k]
        "sites": [{"name": key, "x": s.x, "y": s.y, "radius": s.radius}
                  for key in SITE_NAMES for s in cfg.sites(key)],
        "site_kinds": list(SITE_NAMES),
        "obstacles": [o.model_dump() for o in cfg.obstacles],
        "robot": {"radius": cfg.robot.radius, "comm_range": cfg.robot.communication_range,
                  "collisions": cfg.robot.collisions, "line_of_sight": cfg.robot.line_of_sight},
        "n": len(sim.behaviour_names),
        "behaviours": [{"name": b, "honest": specs[b].honest} for b in names],
        "kind": [names.index(b) for b in sim.behaviour_names],
        "bias": [round(float(b), 5) for b in sim.world.bias],
        "states": list(STATE_NAMES),
        "events": list(EVENT_NAMES),
        "header": list(layout(chain_on(sim))[0]),
        "columns": [[c, np.dtype(t).str] for c, t in layout(chain_on(sim))[1]],
        "chain": _chain_scene(cfg) if chain_on(sim) else None,
    }


def _chain_scene(cfg) -> dict:
    c = cfg.chain
    return {"consensus": c.consensus, "period": c.period, "out_of_turn_delay": c.out_of_turn_delay,
            "backbone": c.backbone, "latency": c.latency, "loss": c.loss, "gas_price": c.gas_price,
            "finality": c.finality}


def _believed(w, site: int) -> tuple[np.ndarray, np.ndarray]:
    """World position each robot's table points at for ``site`` (robot frame: x axis = heading)."""
    dx, dy = _to_world(w, slice(None), w.tab_vec[:, site, 0], w.tab_vec[:, site, 1])
    return w.pos[:, 0] + dx, w.pos[:, 1] + dy


def encode(sim, honest: np.ndarray | None = None, branches: BranchNumbers | None = None) -> bytes:
    """The current state of ``sim`` as one binary frame (see ``COLUMNS``); ``branches``: the chain
    model's branch numbers kept from frame to frame (``ledger.blocklog.BranchNumbers``)."""
    w = sim.world  # re-read every time: the engine may replace arrays between steps
    honest = honest_mask(sim) if honest is None else honest
    items = w.items.astype(np.float64)
    header = np.array([sim.clock, items[honest].sum(), items[~honest].sum(),
                       w.balance[honest].sum(), w.balance[~honest].sum()], dtype="<f8")
    fx, fy = _believed(w, FOOD)
    nx, ny = _believed(w, NEST)
    flags = (w.carrying.astype(np.uint8) * CARRYING
             | w.tab_valid[:, FOOD].astype(np.uint8) * FOOD_VALID
             | w.tab_valid[:, NEST].astype(np.uint8) * NEST_VALID
             | (w.last_site == FOOD).astype(np.uint8) * LAST_FOOD
             | (w.last_site == NEST).astype(np.uint8) * LAST_NEST)
    pend = np.minimum(w.pend_count, 255)
    chain = chain_on(sim)
    if chain:
        header = np.concatenate([header, np.array([w.blk_height[w.chn_canon[0]], w.chn_forks[0], w.chn_reorgs[0]],
                                                  dtype="<f8")])
    values = {
        "x": w.pos[:, 0], "y": w.pos[:, 1], "heading": headings(w), "wealth": w.balance, "items": items,
        "food_x": fx, "food_y": fy, "nest_x": nx, "nest_y": ny,
        "food_age": w.tab_age[:, 0], "nest_age": w.tab_age[:, 1],
        "state": w.state, "flags": flags, "pending_food": pend[:, 0], "pending_nest": pend[:, 1],
    }
    if chain:
        values["chain_height"], values["chain_lag"], values["branch"] = chain_views(w, branches)
    n = len(w.pos)
    padding = bytes(frame_size(n, chain) - _payload_size(n, chain))
    return header.tobytes() + b"".join(np.ascontiguousarray(values[c], dtype=t).tobytes()
                                       for c, t in layout(chain)[1]) + padding


@dataclass(frozen=True)
class Frame:
    """A decoded frame: ``header`` numbers by name and ``columns`` arrays by name."""

    header: dict[str, float]
    columns: dict[str, np.ndarray]

    @property
    def step(self) -> int:
        """The step the frame shows."""
        return int(self.header["step"])


def decode(data: bytes, n: int, chain: bool = False) -> Frame:
    """Inverse of ``encode`` for a swarm of ``n`` robots (what the page does, in Python); ``chain``: the
    frame has the chain model's fields (the scene's ``chain`` is not null)."""
    header, columns = layout(chain)
    if len(data) != frame_size(n, chain):
        raise FormatError(f"a frame of {n} robots has {frame_size(n, chain)} bytes, got {len(data)}")
    head = np.frombuffer(data, "<f8", len(header))
    offset, cols = 8 * len(header), {}
    for c, t in columns:
        cols[c] = np.frombuffer(data, t, n, offset)
        offset += n * np.dtype(t).itemsize
    return Frame(dict(zip(header, head.tolist(), strict=True)), cols)


def event_columns(sim, start: int = 0) -> dict[str, np.ndarray]:
    """The event log from entry ``start`` on, as int32 columns (step, kind, buyer, seller, site)."""
    w = sim.world
    k = int(w.ev_count[0])
    return {c: getattr(w, f"ev_{c}")[start:k].astype("<i4") for c in ("step", "kind", "buyer", "seller", "site")}


def _last_events(w, i: int, last: int) -> list[dict]:
    """The ``last`` most recent events in which robot ``i`` took part, newest first.  Scans the log
    backwards in growing chunks, so a long log does not cost a full pass per frame."""
    k = int(w.ev_count[0])
    found: list[int] = []
    end, chunk = k, 4096
    while end > 0 and len(found) < last:
        start = max(0, end - chunk)
        hit = np.nonzero((w.ev_buyer[start:end] == i) | (w.ev_seller[start:end] == i))[0]
        found.extend((start + hit[::-1]).tolist())
        end, chunk = start, chunk * 4
    out = []
    for e in found[:last]:
        site = int(w.ev_site[e])
        out.append({"step": int(w.ev_step[e]), "kind": EVENT_NAMES[int(w.ev_kind[e])],
                    "buyer": int(w.ev_buyer[e]), "seller": int(w.ev_seller[e]),
                    "site": SITE_NAMES[site] if site >= 0 else None,
                    "stake": round(float(w.ev_stake[e]), 6)})
    return out


def robot_detail(sim, i: int, last: int = LAST_EVENTS, branches: BranchNumbers | None = None) -> dict:
    """What the side panel shows about robot ``i`` beyond the frame's columns: its pending (unconfirmed)
    purchases with the world position each points at, its open transactions as buyer since its last
    deposit, and its last events."""
    w = sim.world
    pending = []
    for site in (FOOD, NEST):
        for k in range(int(w.pend_count[i, site])):
            dx, dy = _to_world(w, i, *w.pend_vec[i, site, k])
            pending.append({"site": SITE_NAMES[site], "seller": int(w.pend_seller[i, site, k]),
                            "age": int(w.pend_age[i, site, k]),
                            "x": round(float(w.pos[i, 0] + dx), 2),
                            "y": round(float(w.pos[i, 1] + dy), 2)})
    sellers, sites, directions = open_transactions(w, i)
    open_tx = [{"seller": int(a), "site": SITE_NAMES[int(b)], "direction": round(float(d), 1)}
               for a, b, d in zip(sellers, sites, directions)]
    out = {"type": "robot", "id": i, "step": sim.clock, "behaviour": sim.behaviour_names[i],
           "state": STATE_NAMES[int(w.state[i])], "pot": round(float(w.pot[i]), 6),
           "pending": pending, "open_transactions": open_tx, "events": _last_events(w, i, last)}
    if chain_on(sim):
        height, lag, branch = chain_views(w, branches)
        steps = max(sim.clock, 1)
        out["chain"] = {"height": int(height[i]), "canonical_height": int(w.blk_height[w.chn_canon[0]]),
                        "lag": int(lag[i]), "branch": int(branch[i]), "head_dropped": bool(w.view_head[i] < 0),
                        "balance_at_head": round(float(w.view_bal[i]), 6),
                        "spendable": round(float(w.view_avail[i]), 6),
                        "gas_paid": round(float(w.gas_paid[i]), 6),
                        "mean_lag": round(float(w.chn_lag_sum[i]) / steps, 3)}
    return out
