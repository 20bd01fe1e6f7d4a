"""Digests of chain-model runs (docs/chain-model.md).

The chain's own numbers are guarded like the paper's (``tests/engine/golden.py``): each case hashes the
robots table, the event and payment logs, the wealth history and the chain's measures of one run bit for
bit.  Work that only restructures the code or makes it faster must leave them alone.  A change that is meant to
move the chain's numbers regenerates them (say why in the
commit and in docs/chain-model.md)::

    python -m tests.ledger.test_chain_digest
"""
from __future__ import annotations

import hashlib
import json

import pytest

import infomarket as im
from infomarket.seeds import run_seed

from ..engine.golden import _hash_frame

#: name -> (experiment, [chain] section, steps, run)
CASES = {
    # every robot signs, gossip only: constant forks, reorganisations, finality by agreement and by depth
    "fig4C poa period 5": ("fig4C", {"consensus": "poa", "period": 5}, 4000, 0),
    # lost messages, gas, a short finality depth, no backbone
    "fig4C poa period 3 loss 0.2 gas finality 8": (
        "fig4C", {"consensus": "poa", "period": 3, "out_of_turn_delay": 2, "loss": 0.2, "gas_price": 1e-7,
                  "finality": 8}, 4000, 1),
    # a backbone with latency, a signer subset, lost gossip
    "fig4C poa period 2 backbone latency 3 signers": (
        "fig4C", {"consensus": "poa", "period": 2, "backbone": True, "latency": 3, "loss": 0.1,
                  "signers": [0, 3, 7, 12, 20]}, 3000, 0),
}

EXPECTED = {
    'fig4C poa period 5': 'ed0faa5218c583a8e9ff046c8a6ae642b76959ebfc3232180919cf4d8e08d15b',
    'fig4C poa period 3 loss 0.2 gas finality 8': '1cb54ffc632353e805e99a3d81db2873363c182e7ee079409d7e5453a0ed5ed1',
    'fig4C poa period 2 backbone latency 3 signers': '8ff45543e4362df856d6b68ed86013af9d5eef676cbabdf1e0f0e799bdc3a121',
}


def digest(name: str) -> str:
    experiment, chain, steps, run = CASES[name]
    cfg = im.load_experiment(experiment).with_overrides(chain=chain)
    sim = im.Simulation(cfg, run_seed(cfg.seed, run), record_events=True, history_every=100)
    r = sim.run(steps)
    h = hashlib.sha256()
    for frame in (r.robots, r.events, r.payments, r.history):
        _hash_frame(h, frame)
    h.update(json.dumps(sim.chain_measures(), sort_keys=True).encode())
    return h.hexdigest()


@pytest.mark.parametrize("name", list(CASES))
def test_chain_runs_are_bit_identical(name):
    assert digest(name) == EXPECTED[name]


if __name__ == "__main__":
    for name in CASES:
        print(f"    {name!r}: {digest(name)!r},")
