"""Each client's share of a server that a team shares (ROS-free).

A client is a goal's sender. rclpy (Jazzy) shows an action server nothing of a goal's sender
(its request header holds only a sequence number, not the DDS writer), so the sender is read
from the goal id: the suite's own clients (``send-goal``, the GUI, ``SynthesisClient``) make
RFC 9562 version-8 UUIDs whose first 48 bits are a tag fixed for the client's lifetime
(:func:`tagged_goal_id`). Any other goal id (rclpy's random version-4 UUIDs: the ros2 command
line, the FlexBE WebUI) is a client of its own, bounded only by the server's overall limits.

Per client, at most ``max_running`` goals run at once and their time limits add up to at most
``max_seconds`` (the worker-seconds they may hold); more wait in arrival order, told their
place, and beyond ``max_waiting`` waiting goals a client's next goal is answered BUSY.
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from dataclasses import dataclass, field

from synthesis_manager.limits import BusyError

#: The bytes of a goal id that name its client (a version-8 UUID's first 48 bits).
ORIGIN_BYTES = 6


def new_origin() -> bytes:
    """A client's tag: random, fixed for the client's lifetime."""
    return os.urandom(ORIGIN_BYTES)


def tagged_goal_id(origin: bytes) -> bytes:
    """A fresh 16-byte goal id naming ``origin``: an RFC 9562 version-8 UUID (custom layout)
    whose first ORIGIN_BYTES are the tag and the rest random."""
    uuid = bytearray(origin[:ORIGIN_BYTES] + os.urandom(16 - ORIGIN_BYTES))
    uuid[6] = 0x80 | (uuid[6] & 0x0F)   # version 8
    uuid[8] = 0x80 | (uuid[8] & 0x3F)   # the RFC variant
    return bytes(uuid)


def goal_origin(goal_id: bytes) -> str:
    """Who sent the goal with this id: its tag when it is a version-8 UUID, else the id itself."""
    goal_id = bytes(goal_id)
    if len(goal_id) == 16 and goal_id[6] >> 4 == 8 and goal_id[8] >> 6 == 2:
        return goal_id[:ORIGIN_BYTES].hex()
    return goal_id.hex()


@dataclass
class Ticket:
    """One goal's place in its client's share."""

    origin: str
    seconds: float
    running: bool = False


@dataclass
class _Client:
    waiting: OrderedDict = field(default_factory=OrderedDict)  # id(ticket) -> ticket, oldest first
    running: int = 0
    seconds: float = 0.0


class ClientShares:
    """Per-client bounds on running goals and on their time limits together."""

    def __init__(self, max_running: int, max_seconds: float, max_waiting: int):
        self.max_running, self.max_seconds, self.max_waiting = max_running, max_seconds, max_waiting
        self._clients: dict[str, _Client] = {}
        self._lock = threading.Lock()

    def join(self, origin: str, seconds: float) -> Ticket:
        """A ticket for a goal of ``origin`` that may hold a worker ``seconds`` (its time limit);
        BusyError when that client already has max_waiting goals waiting."""
        with self._lock:
            client = self._clients.setdefault(origin, _Client())
            if len(client.waiting) >= self.max_waiting:
                raise BusyError(f'this client already has {len(client.waiting)} goals waiting behind its '
                                f'{client.running} running ones (max_client_waiting {self.max_waiting}); '
                                'try again when some have finished', 'max_client_waiting')
            ticket = Ticket(origin, seconds)
            client.waiting[id(ticket)] = ticket
            return ticket

    def admit(self, ticket: Ticket) -> int:
        """0 once ``ticket`` may run (it is then counted as running), else its place among its
        client's waiting goals (1: next)."""
        with self._lock:
            if ticket.running:
                return 0
            client = self._clients[ticket.origin]
            place = list(client.waiting).index(id(ticket)) + 1
            fits = (client.running < self.max_running
                    and (client.running == 0 or client.seconds + ticket.seconds <= self.max_seconds))
            if place > 1 or not fits:
                return place
            del client.waiting[id(ticket)]
            client.running += 1
            client.seconds += ticket.seconds
            ticket.running = True
            return 0

    def leave(self, ticket: Ticket) -> None:
        """The goal ended (or gave up waiting)."""
        with self._lock:
            client = self._clients[ticket.origin]
            if ticket.running:
                client.running -= 1
                client.seconds -= ticket.seconds
                ticket.running = False
            else:
                client.waiting.pop(id(ticket), None)
            if not client.running and not client.waiting:
                del self._clients[ticket.origin]

    def running(self, origin: str) -> int:
        with self._lock:
            client = self._clients.get(origin)
            return client.running if client else 0
