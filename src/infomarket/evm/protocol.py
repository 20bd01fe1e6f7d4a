"""The off-chain half of a sale: the light contract (paper, Methods, last section; docs/model.md §9).

1. The seller, having sensed the buyer's relative pose, computes the path information in the buyer's
   frame (``path_in_buyer_frame``), commits to it with a salted hash, and signs an ``Offer`` (site,
   age, max block, hash) as EIP-712 typed data. The offer is addressed to one buyer because the hash
   commits to information in that buyer's frame.
2. The buyer checks the seller's signature and signs an ``Acceptance`` (the offer, itself, the
   seller's position in its own frame, and its own open round trip: a reveal that lands after the
   buyer's next deposit is refused). That double-signed pair is the ``LightContract``. The revealed
   information is the purchased vector only: the contract derives its direction itself (the vector
   minus the signed seller position), so a seller has nothing to declare and nothing to lie about.
3. The seller submits ``revealInformation(lightContract, pathInfo)``; the contract checks the buyer's
   signature against its own EIP-712 domain (name, version, chain id, contract address), so a
   signature is good for one contract on one chain only.

Signatures are produced by eth-account, which always emits the low-s form the contract requires. The
EIP-712 digests are hashed here directly (``offer_digest``, ``acceptance_digest``: a replay signs tens
of thousands of them); tests check them against eth-account's generic typed-data encoder.
"""
from __future__ import annotations

import functools
import secrets
from dataclasses import dataclass, field

from eth_abi import encode as abi_encode
from eth_account import Account
from eth_keys import keys
from eth_utils import keccak, to_checksum_address

from ..engine.geometry import rotate
from ..engine.world import FOOD, NEST  # noqa: F401  (one definition of the site codes)
from .errors import ChainError
from .units import to_micro

#: Order of the secp256k1 group; a signature's twin with s' = N - s recovers to the same signer.
SECP256K1_N = 0xFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFFEBAAEDCE6AF48A03BBFD25E8CD0364141

_OFFER_FIELDS = [
    {"name": "seller", "type": "address"},
    {"name": "site", "type": "uint8"},
    {"name": "age", "type": "uint32"},
    {"name": "maxBlock", "type": "uint64"},
    {"name": "pathHash", "type": "bytes32"},
]
_ACCEPTANCE_FIELDS = [
    {"name": "offer", "type": "Offer"},
    {"name": "buyer", "type": "address"},
    {"name": "sellerX", "type": "int64"},
    {"name": "sellerY", "type": "int64"},
    {"name": "trip", "type": "uint64"},
]
_DOMAIN_FIELDS = [
    {"name": "name", "type": "string"},
    {"name": "version", "type": "string"},
    {"name": "chainId", "type": "uint256"},
    {"name": "verifyingContract", "type": "address"},
]


@functools.lru_cache(maxsize=4096)
def checksum(address: str | bytes) -> str:
    """``to_checksum_address``, remembered: a client checksums the same few addresses for every message it
    signs and every log it reads (a keccak each time)."""
    return to_checksum_address(address)


@functools.lru_cache(maxsize=1024)
def _address_of(key: bytes) -> str:
    return Account.from_key(key).address


class ProtocolError(ChainError, ValueError):
    """A light contract was malformed or badly signed before it ever reached the chain."""


@dataclass(frozen=True)
class Domain:
    """The EIP-712 domain of one deployed market (what binds a signature to it)."""

    chain_id: int
    verifying_contract: str
    name: str = "InformationMarket"
    version: str = "4"

    def as_dict(self) -> dict:
        """The EIP-712 domain as signing libraries take it (``chainId``, ``verifyingContract`` checksummed)."""
        return {
            "name": self.name,
            "version": self.version,
            "chainId": self.chain_id,
            "verifyingContract": checksum(self.verifying_contract),
        }


@dataclass(frozen=True)
class PathInfo:
    """Revealed path information: the purchased vector in the buyer's frame, micro units."""

    x: int
    y: int
    salt: bytes = field(default_factory=lambda: secrets.token_bytes(32))

    @classmethod
    def from_floats(cls, x: float, y: float, salt: bytes | None = None) -> PathInfo:
        """Encode a purchased vector (arena units)."""
        return cls(to_micro(x), to_micro(y), salt or secrets.token_bytes(32))

    def digest(self) -> bytes:
        """The commitment the offer carries: ``keccak256(abi.encode(x, y, salt))``."""
        return keccak(abi_encode(["int64", "int64", "bytes32"], list(self.as_abi())))

    def as_abi(self) -> tuple:
        """The path as the contract's ABI tuple (x, y, salt)."""
        return (self.x, self.y, self.salt)


@dataclass(frozen=True)
class Offer:
    """A seller's signed-to-be offer: the information is hidden behind ``path_hash``."""

    seller: str
    site: int
    age: int
    max_block: int
    path_hash: bytes

    def as_abi(self) -> tuple:
        """The offer as the contract's ABI tuple (seller, site, age, maxBlock, pathHash)."""
        return (checksum(self.seller), self.site, self.age, self.max_block, self.path_hash)

    def message(self) -> dict:
        """The offer as the EIP-712 message the seller signs, keyed by the contract's field names."""
        return dict(zip(("seller", "site", "age", "maxBlock", "pathHash"), self.as_abi()))


@dataclass(frozen=True)
class LightContract:
    """The double-signed agreement; ``v, r, s`` is the buyer's signature over the acceptance."""

    offer: Offer
    offer_signature: bytes
    buyer: str
    seller_x: int
    seller_y: int
    trip: int
    v: int
    r: bytes
    s: bytes

    def as_abi(self) -> tuple:
        """The agreement as the contract's ABI tuple: the offer, the buyer, the seller's position, the trip and the
        signature."""
        return (self.offer.as_abi(), checksum(self.buyer), self.seller_x, self.seller_y,
                self.trip, self.v, self.r, self.s)


def offer_typed_data(domain: Domain, offer: Offer) -> dict:
    """EIP-712 message the seller signs."""
    return {
        "types": {"EIP712Domain": _DOMAIN_FIELDS, "Offer": _OFFER_FIELDS},
        "primaryType": "Offer",
        "domain": domain.as_dict(),
        "message": offer.message(),
    }


def acceptance_typed_data(domain: Domain, offer: Offer, buyer: str, seller_x: int, seller_y: int,
                          trip: int) -> dict:
    """EIP-712 message the buyer signs (the contract's ``acceptanceDigest`` hashes the same thing)."""
    return {
        "types": {"EIP712Domain": _DOMAIN_FIELDS, "Offer": _OFFER_FIELDS, "Acceptance": _ACCEPTANCE_FIELDS},
        "primaryType": "Acceptance",
        "domain": domain.as_dict(),
        "message": {"offer": offer.message(), "buyer": checksum(buyer),
                    "sellerX": seller_x, "sellerY": seller_y, "trip": trip},
    }


_DOMAIN_TYPEHASH = keccak(text="EIP712Domain(string name,string version,uint256 chainId,address verifyingContract)")
_OFFER_TYPE = "Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)"
_OFFER_TYPEHASH = keccak(text=_OFFER_TYPE)
_ACCEPTANCE_TYPEHASH = keccak(text="Acceptance(Offer offer,address buyer,int64 sellerX,int64 sellerY,uint64 trip)"
                                    + _OFFER_TYPE)


@functools.lru_cache(maxsize=64)
def _separator(domain: Domain) -> bytes:
    return keccak(abi_encode(["bytes32", "bytes32", "bytes32", "uint256", "address"],
                             [_DOMAIN_TYPEHASH, keccak(text=domain.name), keccak(text=domain.version),
                              domain.chain_id, checksum(domain.verifying_contract)]))


@functools.lru_cache(maxsize=256)
def _offer_hash(offer: Offer) -> bytes:
    """The offer's struct hash; remembered, as the seller signs it, the buyer checks it and signs over it."""
    return keccak(abi_encode(["bytes32", "address", "uint8", "uint32", "uint64", "bytes32"],
                             [_OFFER_TYPEHASH, *offer.as_abi()]))


def offer_digest(domain: Domain, offer: Offer) -> bytes:
    """The EIP-712 digest of ``offer_typed_data``."""
    return keccak(b"\x19\x01" + _separator(domain) + _offer_hash(offer))


def acceptance_digest(domain: Domain, offer: Offer, buyer: str, seller_x: int, seller_y: int, trip: int) -> bytes:
    """The EIP-712 digest of ``acceptance_typed_data`` (what the contract's ``acceptanceDigest`` returns)."""
    struct = keccak(abi_encode(["bytes32", "bytes32", "address", "int64", "int64", "uint64"],
                               [_ACCEPTANCE_TYPEHASH, _offer_hash(offer), checksum(buyer), seller_x, seller_y,
                                trip]))
    return keccak(b"\x19\x01" + _separator(domain) + struct)


@functools.lru_cache(maxsize=1024)
def _private_key(key: bytes) -> keys.PrivateKey:
    """The key object (it derives its public key when made: once per robot, not once per signature)."""
    return keys.PrivateKey(key)


def _sign(key: bytes, digest: bytes) -> tuple[int, bytes, bytes]:
    """(v, r, s) of a low-s signature of ``digest`` (v is 27 or 28)."""
    sig = _private_key(bytes(key)).sign_msg_hash(digest)
    return sig.v + 27, sig.r.to_bytes(32, "big"), sig.s.to_bytes(32, "big")


_DEPOSIT_TYPEHASH = keccak(text="Deposit(address robot,uint64 trip)")


def deposit_digest(domain: Domain, robot: str, trip: int) -> bytes:
    """The EIP-712 digest of ``Deposit(robot, trip)`` (the contract's ``depositDigest``): what the robot
    signs to end round trip ``trip`` with a deposit, and what the nest signs to acknowledge it."""
    struct = keccak(abi_encode(["bytes32", "address", "uint64"], [_DEPOSIT_TYPEHASH, checksum(robot), trip]))
    return keccak(b"\x19\x01" + _separator(domain) + struct)


def sign_deposit(key: bytes, domain: Domain, robot: str, trip: int) -> tuple[int, bytes, bytes]:
    """(v, r, s) of ``key``'s signature over ``Deposit(robot, trip)``."""
    return _sign(key, deposit_digest(domain, robot, trip))


def sign_offer(seller_key: bytes, domain: Domain, offer: Offer) -> bytes:
    """The seller's 65-byte signature over its offer."""
    if _address_of(bytes(seller_key)) != checksum(offer.seller):
        raise ProtocolError("an offer can only be signed by the seller it names")
    v, r, s = _sign(seller_key, offer_digest(domain, offer))
    return r + s + bytes([v])


def accept_offer(buyer_key: bytes, domain: Domain, offer: Offer, offer_signature: bytes,
                 seller_position: tuple[float, float], trip: int) -> LightContract:
    """The buyer's side: check who made the offer, then sign the acceptance.

    ``seller_position`` is the seller's position in the buyer's frame, as the buyer senses it; signing
    it lets anyone audit, after the reveal, that the revealed direction is that of the revealed vector
    minus this position. ``trip`` is the buyer's open round trip (the contract's ``roundTrip(buyer)``):
    the contract refuses the reveal once the buyer has deposited. How many offers a buyer accepts per
    round trip is capped by its client (``market.AcceptanceBook``), not here.
    """
    signer = Account._recover_hash(offer_digest(domain, offer), signature=offer_signature)
    if signer != checksum(offer.seller):
        raise ProtocolError(f"offer claims seller {offer.seller} but is signed by {signer}")
    buyer = _address_of(bytes(buyer_key))
    sx, sy = to_micro(seller_position[0]), to_micro(seller_position[1])
    v, r, s = _sign(buyer_key, acceptance_digest(domain, offer, buyer, sx, sy, trip))
    return LightContract(offer, offer_signature, buyer, sx, sy, trip, v, r, s)


def path_in_buyer_frame(vector: tuple[float, float], heading_offset_deg: float,
                        seller_position: tuple[float, float]) -> tuple[float, float]:
    """What the seller reveals (docs/model.md §4): its vector rotated into the buyer's frame by
    ``heading_seller - heading_buyer``, plus its own position in the buyer's frame, as ``(x, y)``.
    The contract subtracts the position again to get the rotated vector the outlier rule compares.
    """
    rx, ry = rotate(vector[0], vector[1], heading_offset_deg)
    return rx + seller_position[0], ry + seller_position[1]
