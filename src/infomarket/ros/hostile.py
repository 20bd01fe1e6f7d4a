"""Hostile messages, sent by the world before each sale when ``--fault hostile`` is given: a malformed
offer, a forged offer (signed by a key that is not the seller's) and a replayed acceptance (one of an
earlier step's sale, sent to its seller again: sales of disjoint robots run at once, so "earlier" is
by the step of the sale, not by the order the acceptances were heard). Each agent must refuse and
log every one and go on; the ledger must still equal the engine's.
"""
from __future__ import annotations

import secrets

from eth_keys import keys

from ..evm.protocol import Offer, offer_digest
from . import wire


class Hostile:
    """Publishes the three kinds of hostile message on the agents' market topics."""

    def __init__(self, world, domain, addresses: list[str]):
        from std_msgs.msg import UInt8MultiArray

        self.world, self.domain, self.addresses = world, domain, addresses
        self._Bytes = UInt8MultiArray
        node = world.node
        q = wire.qos()
        self.offers = [node.create_publisher(UInt8MultiArray, wire.offers(i), q) for i in range(len(addresses))]
        self.accepts = [node.create_publisher(UInt8MultiArray, wire.acceptances(i), q)
                        for i in range(len(addresses))]
        self.last: dict[int, tuple[int, bytes]] = {}  # seller -> (step, the last acceptance it was sent)
        self.steps: dict[int, int] = {}  # task id -> the step of its sale
        self.sent = 0
        for i in range(len(addresses)):
            node.create_subscription(UInt8MultiArray, wire.acceptances(i), lambda m, i=i: self._heard(i, m), q)

    def _heard(self, seller: int, msg) -> None:
        data = bytes(msg.data)
        try:
            task_id, _ = wire.decode_acceptance(data)
        except wire.WireError:
            return  # one of its own hostile messages, or another's
        if task_id in self.steps:
            self.last[seller] = (self.steps[task_id], data)

    def __call__(self, buyer: int, seller: int, task_id: int, site: int, age: int, step: int) -> None:
        def send(pub, data) -> None:
            pub.publish(self._Bytes(data=list(data)))
            self.sent += 1

        send(self.offers[buyer], secrets.token_bytes(37))  # malformed
        offer = Offer(self.addresses[seller], site, age, 2**40, secrets.token_bytes(32))
        sig = keys.PrivateKey(secrets.token_bytes(32)).sign_msg_hash(offer_digest(self.domain, offer))
        forged = sig.r.to_bytes(32, "big") + sig.s.to_bytes(32, "big") + bytes([sig.v + 27])
        send(self.offers[buyer], wire.encode_offer(task_id, offer, forged))  # forged: another key signed it
        self.steps[task_id] = step
        for old_seller, (old_step, data) in list(self.last.items()):
            if old_step < step:  # a sale of an earlier step: over for its seller
                send(self.accepts[old_seller], data)  # replayed
                break
