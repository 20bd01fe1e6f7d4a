"""The viewer with the chain model on (docs/chain-model.md): each robot's chain height, lag and branch in
the frames, the panel's details and ``Simulation.snapshot``; nothing of it without the chain.  The
expected views come from the partition story of tests/ledger/test_chain.py, worked by hand."""
from __future__ import annotations

import numpy as np

import infomarket as im
from infomarket.config.load import validate
from infomarket.ledger.poa import mempool
from infomarket.viewer import frames as fr
from infomarket.viewer.recording import record


def _partitioned():
    """Side A = robots 0, 1; side B = robots 2, 3, out of each other's range; signers (0, 2); P = 2, delay
    3.  Robots 1 and 3 deposit at step 0.  Robot 2 (in turn) makes B1 at step 2, heard by robot 3 at step
    3; robot 0 (out of turn) makes A1 at step 5 on genesis: a fork, B1 heavier (2 against 1), canonical.
    After step 5: heads B1, B1 for robots 2, 3; A1 for robot 0; genesis for robot 1 (it hears A1 at step 6)."""
    cfg = validate({"name": "chain_view", "steps": 1000, "robot": {"speed": 1e-9, "communication_range": 50.0},
                    "swarm": {"robots": 4, "groups": [{"behaviour": "naive", "count": 4}]},
                    "chain": {"consensus": "poa", "period": 2, "out_of_turn_delay": 3, "signers": [0, 2]}})
    sim = im.Simulation(cfg, 1, record_events=True)
    sim.world.pos[:] = np.array([(100.0, 100.0), (130.0, 100.0), (1000.0, 500.0), (1030.0, 500.0)])
    mempool.send_deposit(sim._view, 1)
    mempool.send_deposit(sim._view, 3)
    sim.step(5)
    return sim


def test_a_fork_shows_in_the_frame_the_panel_and_the_snapshot():
    sim = _partitioned()
    scene = fr.scene(sim)
    assert scene["chain"]["period"] == 2 and "branch" in dict(scene["columns"])
    f = fr.decode(fr.encode(sim), 4, chain=True)
    assert (f.header["chain_height"], f.header["chain_forks"], f.header["chain_reorgs"]) == (1, 1, 0)
    assert f.columns["chain_height"].tolist() == [1, 0, 1, 1]
    assert f.columns["chain_lag"].tolist() == [0, 1, 0, 0]
    assert f.columns["branch"].tolist() == [1, 0, 0, 0]  # robot 0 on A1: off the canonical branch
    d = fr.robot_detail(sim, 1)["chain"]
    assert (d["height"], d["canonical_height"], d["lag"], d["branch"]) == (0, 1, 1, 0)
    # robot 1 lagged 0 blocks for steps 1-2 and 1 block for steps 3-5 (B1 canonical from step 2): 3 / 5
    assert d["mean_lag"] == 0.6
    snap = sim.snapshot()["chain"]
    assert (snap["height"], snap["forks"], snap["head_height"], snap["lag"], snap["branch"]) == (
        1, 1, [1, 0, 1, 1], [0, 1, 0, 0], [1, 0, 0, 0])
    # reconnected: robot 0 hears B1 and makes B2 on it, everyone follows: one branch again
    sim.world.pos[:] = np.array([(1000.0, 520.0), (1010.0, 540.0), (1000.0, 500.0), (1030.0, 500.0)])
    sim.step(2)
    f = fr.decode(fr.encode(sim), 4, chain=True)
    assert f.columns["branch"].tolist() == [0, 0, 0, 0] and f.columns["chain_height"].tolist() == [2] * 4


def test_frames_without_the_chain_are_as_before(fig2b):
    sim = im.Simulation(fig2b, 5)
    scene = fr.scene(sim)
    assert scene["chain"] is None and scene["header"] == list(fr.HEADER)
    assert scene["columns"] == [[c, np.dtype(t).str] for c, t in fr.COLUMNS]
    assert len(fr.encode(sim)) == fr.frame_size(25) and "chain" not in fr.robot_detail(sim, 0)
    assert sim.snapshot()["chain"] is None


def test_the_chain_layout_is_aligned_and_a_recording_decodes():
    header, columns = fr.layout(chain=True)
    offset = 8 * len(header)
    for _, t in columns:
        size = np.dtype(t).itemsize
        assert offset % size == 0
        offset += 7 * size
    assert offset == 64 + 7 * 57 == 463  # 8 header numbers; 13 float32 and 5 uint8 columns
    assert fr.frame_size(7, chain=True) == 464  # padded to a multiple of 8


def test_a_chain_frame_is_padded_so_frames_laid_end_to_end_stay_aligned():
    """A replay lays its frames end to end and the page reads frame k's float64 header at k times the
    frame size, so the size must be a multiple of 8: 64 + 57 n bytes is not when n is not (25 robots:
    1 489 bytes, padded to 1 496)."""
    assert fr.frame_size(25, chain=True) == 1496 and fr.frame_size(24, chain=True) == 64 + 24 * 57
    assert all(fr.frame_size(n, chain) % 8 == 0 for n in range(1, 65) for chain in (False, True))
    sim = _partitioned()
    cfg = sim.config.with_overrides(swarm={"robots": 5, "groups": [{"behaviour": "naive", "count": 5}]})
    data = fr.encode(im.Simulation(cfg, 1))
    assert len(data) == fr.frame_size(5, chain=True) == 64 + 5 * 57 + 3 and data[-3:] == bytes(3)
    cfg = im.load_experiment("fig4C").with_overrides(steps=60, chain={"consensus": "poa", "period": 5})
    rec = record(cfg, 2, every=20)
    last = rec.frame(len(rec.frames) - 1)
    assert last.step == 60 and last.header["chain_height"] >= 1
    assert (last.columns["chain_lag"] == last.header["chain_height"] - last.columns["chain_height"]).all()


def test_a_branch_keeps_its_number_from_frame_to_frame_while_it_lasts():
    """A hand-made block tree: genesis 0; canonical 0 -> 1 -> 2; branch A leaves it at block 3 (on 0,
    hash 900), branch B at block 4 (on 1, hash 100; block 5 on it).  Frame 1: robots on 2, 3, 5 and a
    dropped head: new branches are numbered in hash order, B 1 and A 2.  Frame 2: robot 2 is back on the
    canonical head, B is gone, and A keeps its 2 (numbered afresh, as a viewer without memory would, A
    would become 1 and change colour).  Frame 3: branch C (block 6 on 0) takes the lowest free number, 1."""
    from types import SimpleNamespace

    from infomarket.ledger.blocklog import DROPPED, BranchNumbers, chain_views

    w = SimpleNamespace(
        chn_canon=np.array([2]), blk_live=np.ones(7, bool),
        blk_parent=np.array([-1, 0, 1, 0, 1, 4, 0]), blk_height=np.array([0, 1, 2, 1, 2, 3, 1]),
        blk_hash=np.array([7, 8, 9, 900, 100, 300, 50]),
        view_head=np.array([2, 3, 5, -1]), view_height=np.array([2, 1, 3, 1]))
    numbers = BranchNumbers()
    height, lag, branch = chain_views(w, numbers)
    assert branch.tolist() == [0, 2, 1, DROPPED]
    assert height.tolist() == [2, 1, 3, 1] and lag.tolist() == [0, 1, -1, 1]
    w.view_head = np.array([2, 3, 2, -1])
    assert chain_views(w, numbers)[2].tolist() == [0, 2, 0, DROPPED]
    assert chain_views(w)[2].tolist() == [0, 1, 0, DROPPED]  # afresh: what a frame without memory shows
    w.view_head = np.array([2, 3, 2, 6])
    assert chain_views(w, numbers)[2].tolist() == [0, 2, 0, 1]

