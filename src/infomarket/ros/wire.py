"""What travels over ROS 2: topic names, QoS, and the bytes of the protocol's messages.

Only the installable message packages are used (std_msgs, geometry_msgs, nav_msgs, rosgraph_msgs), so a
robot's own code in any language can speak the protocol with no custom message build. The signed
messages (offer, acceptance, deposit) travel as ``std_msgs/UInt8MultiArray`` holding their ABI encoding,
the same bytes the contract decodes; the world's tasks and the agents' reports are ``std_msgs/String``
holding JSON. Every decoder raises ``WireError`` on anything malformed, which the agent refuses and logs.
"""
from __future__ import annotations

import json

from eth_abi import decode as abi_decode
from eth_abi import encode as abi_encode

from ..errors import FormatError
from ..evm.protocol import LightContract, Offer, checksum

CLOCK = "/clock"
HELLO = "/market/hello"      # agent -> world: {"robot", "address", "pid"} (std_msgs/String, JSON)
DONE = "/market/done"        # agent -> world: a task's outcome (std_msgs/String, JSON)
DEPOSIT = "/market/deposit"  # agent -> nest: the robot's signed Deposit(robot, trip) (UInt8MultiArray)


def odom(robot: int) -> str:
    """nav_msgs/Odometry: the robot's pose in the arena frame, stamped with /clock time."""
    return f"/robot_{robot}/odom"


def neighbours(robot: int) -> str:
    """std_msgs/Float64MultiArray: rows (robot id, x, y) of the robots it senses, in its own frame."""
    return f"/robot_{robot}/neighbours"


def task(robot: int) -> str:
    """std_msgs/String (JSON): what the robot's behaviour decided this step (sell, buy, deposit)."""
    return f"/robot_{robot}/market/task"


def offers(robot: int) -> str:
    """std_msgs/UInt8MultiArray: offers addressed to this robot (as buyer)."""
    return f"/robot_{robot}/market/offer"


def acceptances(robot: int) -> str:
    """std_msgs/UInt8MultiArray: acceptances (light contracts) addressed to this robot (as seller)."""
    return f"/robot_{robot}/market/acceptance"


def ask(robot: int) -> str:
    """std_msgs/String (JSON): the agent's questions to its robot's controller (``decide.py``)."""
    return f"/robot_{robot}/market/ask"


def decision(robot: int) -> str:
    """std_msgs/String (JSON): the controller's answers, ``{"id", "question", "yes"}``."""
    return f"/robot_{robot}/market/decision"


def qos():
    """Reliable, keep the last 100, volatile: lost messages (drops, a restarted agent) are resent by
    the protocol's own retries, never replayed by the middleware."""
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)


class WireError(FormatError):
    """A message that is not what its topic carries."""


_OFFER = ["uint64", "address", "uint8", "uint32", "uint64", "bytes32", "bytes"]
_ACCEPT = _OFFER + ["address", "int64", "int64", "uint64", "uint8", "bytes32", "bytes32"]
_DEPOSIT = ["uint64", "address", "uint64", "uint8", "bytes32", "bytes32"]


def _decode(types: list[str], data: bytes) -> tuple:
    try:
        return abi_decode(types, bytes(data))
    except Exception as exc:  # noqa: BLE001 - eth_abi raises several kinds on short or bad input
        raise WireError(f"malformed message ({len(data)} bytes): {type(exc).__name__}") from None


def encode_offer(task_id: int, offer: Offer, signature: bytes) -> bytes:
    return abi_encode(_OFFER, [task_id, *offer.as_abi(), signature])


def decode_offer(data: bytes) -> tuple[int, Offer, bytes]:
    task_id, seller, site, age, max_block, path_hash, sig = _decode(_OFFER, data)
    if len(sig) != 65:
        raise WireError(f"offer signature of {len(sig)} bytes, not 65")
    return task_id, Offer(checksum(seller), site, age, max_block, path_hash), sig


def encode_acceptance(task_id: int, lc: LightContract) -> bytes:
    return abi_encode(_ACCEPT, [task_id, *lc.offer.as_abi(), lc.offer_signature, checksum(lc.buyer), lc.seller_x,
                                lc.seller_y, lc.trip, lc.v, lc.r, lc.s])


def decode_acceptance(data: bytes) -> tuple[int, LightContract]:
    fields = _decode(_ACCEPT, data)
    task_id, offer, sig = fields[0], Offer(checksum(fields[1]), *fields[2:6]), fields[6]
    buyer, sx, sy, trip, v, r, s = fields[7:]
    return task_id, LightContract(offer, sig, checksum(buyer), sx, sy, trip, v, r, s)


def encode_deposit(task_id: int, robot: str, trip: int, vrs: tuple[int, bytes, bytes]) -> bytes:
    return abi_encode(_DEPOSIT, [task_id, robot, trip, *vrs])


def decode_deposit(data: bytes) -> tuple[int, str, int, tuple[int, bytes, bytes]]:
    task_id, robot, trip, v, r, s = _decode(_DEPOSIT, data)
    return task_id, checksum(robot), trip, (v, r, s)


def decode_json(text: str, *keys: str) -> dict:
    """A JSON object holding at least ``keys``."""
    try:
        value = json.loads(text)
    except ValueError:
        raise WireError("malformed JSON") from None
    if not isinstance(value, dict) or any(k not in value for k in keys):
        raise WireError(f"a JSON object with {', '.join(keys)} expected")
    return value


def lc_to_json(lc: LightContract) -> str:
    """A light contract as text, for the agent's state on disk."""
    return encode_acceptance(0, lc).hex()


def lc_from_json(text: str) -> LightContract:
    return decode_acceptance(bytes.fromhex(text))[1]
