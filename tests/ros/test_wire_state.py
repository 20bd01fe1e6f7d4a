"""The agent's pieces that need no ROS 2: its key file, its state on disk, and the bytes on the wire."""
from __future__ import annotations


import pytest
from eth_account import Account

from infomarket.errors import UsageError
from infomarket.evm.protocol import Domain, Offer, PathInfo, accept_offer, sign_offer
from infomarket.ros import wire
from infomarket.ros.state import AgentState, load_or_create_key

DOMAIN = Domain(31337, "0x" + "11" * 20)


def test_key_file_is_private_and_kept(tmp_path):
    key = load_or_create_key(tmp_path / "r")
    path = tmp_path / "r" / "key"
    assert path.stat().st_mode & 0o777 == 0o600
    assert load_or_create_key(tmp_path / "r") == key  # a restart finds the same key
    path.chmod(0o644)
    with pytest.raises(UsageError, match="chmod 600"):
        load_or_create_key(tmp_path / "r")


def test_state_survives_a_restart_and_lists_unrevealed_contracts(tmp_path):
    state = AgentState(tmp_path)
    state.put(7, {"kind": "sell", "lc": "00"})
    state.put(8, {"kind": "sell", "lc": "00", "result": {"gas": 1}})
    state.put(9, {"kind": "buy"})
    again = AgentState(tmp_path)
    assert again.get(8) == {"kind": "sell", "lc": "00", "result": {"gas": 1}}
    assert [k for k, _ in again.unrevealed()] == [7]


def _light_contract():
    seller, buyer = Account.create(), Account.create()
    info = PathInfo.from_floats(1.5, -2.25)
    offer = Offer(seller.address, 1, 40, 1000, info.digest())
    sig = sign_offer(seller.key, DOMAIN, offer)
    return offer, sig, accept_offer(buyer.key, DOMAIN, offer, sig, (0.5, 0.25), 3)


def test_offer_and_acceptance_bytes_round_trip():
    offer, sig, lc = _light_contract()
    assert wire.decode_offer(wire.encode_offer(5, offer, sig)) == (5, offer, sig)
    assert wire.decode_acceptance(wire.encode_acceptance(5, lc)) == (5, lc)
    assert wire.lc_from_json(wire.lc_to_json(lc)) == lc
    vrs = (27, b"\x01" * 32, b"\x02" * 32)
    assert wire.decode_deposit(wire.encode_deposit(9, lc.buyer, 3, vrs)) == (9, lc.buyer, 3, vrs)


# fixed bytes: a random parameter would name the test differently in each pytest-xdist worker
@pytest.mark.parametrize("data", [b"", bytes(range(37)), bytes(range(200, 237)), b"\x00" * 31],
                         ids=["empty", "37-counting", "37-high", "31-zeros"])
def test_malformed_bytes_are_a_wire_error(data):
    for decode in (wire.decode_offer, wire.decode_acceptance, wire.decode_deposit):
        with pytest.raises(wire.WireError):
            decode(data)


def test_offer_with_a_short_signature_is_refused():
    offer, sig, _ = _light_contract()
    with pytest.raises(wire.WireError, match="65"):
        wire.decode_offer(wire.encode_offer(1, offer, sig[:64]))


@pytest.mark.parametrize("text", ["{", "[]", '{"robot": 1}'])
def test_json_messages_need_their_keys(text):
    with pytest.raises(wire.WireError):
        wire.decode_json(text, "robot", "kind")
