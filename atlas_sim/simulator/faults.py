"""Fault injection for capabilities (control modes and actions).

A :class:`FaultSpec` combines three independent triggers; an attempt fails
when any of them fires:

* ``always``       every attempt fails;
* ``fail_first``   the first *k* attempts fail, later ones are unaffected;
* ``probability``  each attempt fails with probability *p*.

Only attempts that passed the discrete checks (mode transition allowed,
preconditions met) count as attempts.  Probabilistic draws come from one
``random.Random`` per capability, seeded from ``(seed, capability)``, so a
capability's sequence of outcomes does not depend on what else was requested.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Any, Dict, Mapping, Optional


@dataclass(frozen=True)
class FaultSpec:
    always: bool = False
    fail_first: int = 0
    probability: float = 0.0

    def __post_init__(self) -> None:
        if self.fail_first < 0:
            raise ValueError("fail_first must be >= 0")
        if not 0.0 <= self.probability <= 1.0:
            raise ValueError("probability must be within [0, 1]")

    @classmethod
    def from_dict(cls, entry: Mapping[str, Any]) -> "FaultSpec":
        unknown = set(entry) - {"always", "fail_first", "probability"}
        if unknown:
            raise ValueError(f"unknown fault keys {sorted(unknown)}")
        return cls(
            always=bool(entry.get("always", False)),
            fail_first=int(entry.get("fail_first", 0)),
            probability=float(entry.get("probability", 0.0)),
        )


class FaultInjector:
    """Decides, attempt by attempt, whether a capability suffers an injected fault."""

    def __init__(self, seed: int = 0, faults: Optional[Mapping[str, FaultSpec]] = None) -> None:
        self.seed = seed
        self._faults: Dict[str, FaultSpec] = dict(faults or {})
        self._attempts: Dict[str, int] = {}
        self._streams: Dict[str, random.Random] = {}

    def set_fault(self, capability: str, spec: Optional[FaultSpec]) -> None:
        """Install (or with ``None`` remove) the fault of a capability; resets its counters."""
        if spec is None:
            self._faults.pop(capability, None)
        else:
            self._faults[capability] = spec
        self._attempts.pop(capability, None)
        self._streams.pop(capability, None)

    def attempts(self, capability: str) -> int:
        return self._attempts.get(capability, 0)

    def fault_for_attempt(self, capability: str) -> Optional[str]:
        """Count one attempt; return a reason if it must fail, else ``None``."""
        attempt = self._attempts.get(capability, 0) + 1
        self._attempts[capability] = attempt
        spec = self._faults.get(capability)
        if spec is None:
            return None
        if spec.always:
            return f"injected fault: {capability} always fails"
        if attempt <= spec.fail_first:
            return f"injected fault: attempt {attempt} of {capability} (first {spec.fail_first} fail)"
        if spec.probability > 0.0 and self._stream(capability).random() < spec.probability:
            return f"injected fault: {capability} failed with probability {spec.probability}"
        return None

    def _stream(self, capability: str) -> random.Random:
        if capability not in self._streams:
            self._streams[capability] = random.Random(f"{self.seed}:{capability}")
        return self._streams[capability]
