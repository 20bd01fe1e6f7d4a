"""The off-chain light contract and the fixed-point encodings (infomarket.evm.protocol, .units)."""
from __future__ import annotations

import pytest
from eth_account import Account
from eth_account.messages import encode_typed_data
from eth_utils import keccak

from infomarket.evm.protocol import (
    Domain,
    Offer,
    PathInfo,
    ProtocolError,
    accept_offer,
    acceptance_digest,
    acceptance_typed_data,
    offer_digest,
    offer_typed_data,
    path_in_buyer_frame,
    sign_offer,
)
from infomarket.evm.units import (
    FULL_TURN,
    from_units,
    share_to_wad,
    to_micro,
    to_microdegrees,
    to_units,
)


def test_paper_amounts_are_exact_in_ledger_units():
    assert to_units(1) == 1_000_000_000
    assert to_units(0.04) == 40_000_000
    assert to_units(0.05) == 50_000_000
    assert share_to_wad(0.5) == 5 * 10**17
    assert from_units(1_083_333_333) == pytest.approx(1.083333333)


def test_directions_wrap_into_one_turn():
    assert to_microdegrees(26.077063) == 26_077_063
    assert to_microdegrees(-1.0) == FULL_TURN - 1_000_000
    assert to_microdegrees(360.0) == 0
    assert to_microdegrees(359.9999999) == 0  # rounds up to a full turn, which is 0


def test_positions_must_fit_int64():
    assert to_micro(-2.5) == -2_500_000
    with pytest.raises(ValueError, match="int64"):
        to_micro(1e13)


def test_path_information_is_the_rotated_offer_plus_the_seller_position():
    x, y = path_in_buyer_frame((10.0, 0.0), 90.0, (3.0, -4.0))
    assert (x, y) == pytest.approx((3.0, 6.0))
    x, y = path_in_buyer_frame((1.0, 1.0), 180.0, (100.0, 100.0))
    assert (x, y) == pytest.approx((99.0, 99.0))


def test_path_commitment_binds_every_field():
    info = PathInfo(1, 2, b"\x01" * 32)
    changed = [PathInfo(9, 2, info.salt), PathInfo(1, 9, info.salt), PathInfo(1, 2, b"\x02" * 32)]
    assert len({info.digest(), *(c.digest() for c in changed)}) == 4
    assert PathInfo.from_floats(1.0, 2.0).salt != PathInfo.from_floats(1.0, 2.0).salt


def test_hand_hashed_digests_equal_eth_accounts_typed_data_encoding():
    domain = Domain(7, "0x" + "44" * 20)
    offer = _offer("0x" + "55" * 20)
    for typed, digest in ((offer_typed_data(domain, offer), offer_digest(domain, offer)),
                          (acceptance_typed_data(domain, offer, "0x" + "66" * 20, -3, 4, 11),
                           acceptance_digest(domain, offer, "0x" + "66" * 20, -3, 4, 11))):
        signable = encode_typed_data(full_message=typed)
        assert digest == keccak(b"\x19" + signable.version + signable.header + signable.body)


def _offer(seller: str, domain_block: int = 10) -> Offer:
    return Offer(seller, 1, 7, domain_block, b"\x11" * 32)


def test_buyer_refuses_an_offer_signed_by_someone_else():
    seller, impostor, buyer = (Account.create() for _ in range(3))
    domain = Domain(1, "0x" + "22" * 20)
    offer = _offer(seller.address)
    forged = sign_offer(impostor.key, domain, Offer(impostor.address, 1, 7, 10, b"\x11" * 32))
    with pytest.raises(ProtocolError, match="signed by"):
        accept_offer(buyer.key, domain, offer, forged, (0.0, 0.0), 0)
    with pytest.raises(ProtocolError):
        sign_offer(impostor.key, domain, offer)


def test_acceptance_signature_recovers_to_the_buyer_and_signs_the_seller_position():
    seller, buyer = Account.create(), Account.create()
    domain = Domain(5, "0x" + "33" * 20)
    offer = _offer(seller.address)
    lc = accept_offer(buyer.key, domain, offer, sign_offer(seller.key, domain, offer), (1.5, -2.0), 3)
    assert (lc.seller_x, lc.seller_y, lc.trip) == (1_500_000, -2_000_000, 3)
    message = encode_typed_data(full_message=acceptance_typed_data(domain, offer, buyer.address, 1_500_000, -2_000_000,
                                                                          3))
    assert Account.recover_message(message, vrs=(lc.v, lc.r, lc.s)) == buyer.address
    # eth-account only ever emits low-s signatures, which the contract requires.
    assert int.from_bytes(lc.s, "big") <= 0x7FFFFFFFFFFFFFFFFFFFFFFFFFFFFFFF5D576E7357A4501DDFE92F46681B20A0


def test_python_and_contract_hash_the_acceptance_identically(make_market, robots):
    market = make_market("outlier")
    seller, buyer = robots[1], robots[0]
    info = PathInfo.from_floats(12.0, -3.0)
    lc = market.light_contract(seller, buyer, 0, 42, info, (-7.25, 0.5))
    on_chain = market.view("acceptanceDigest", lc.offer.as_abi(), buyer.address, lc.seller_x, lc.seller_y, 5)
    typed = acceptance_typed_data(market.domain, lc.offer, buyer.address, lc.seller_x, lc.seller_y, 5)
    signable = encode_typed_data(full_message=typed)
    assert on_chain == keccak(b"\x19" + signable.version + signable.header + signable.body)
    assert market.domain.verifying_contract == market.address
    assert market.domain.chain_id == market.backend.chain_id
