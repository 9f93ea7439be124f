"""Identity readers: the barcode readers that tell which plate a holder has, and that sometimes fail.

Why: a presence sensor (a light barrier, a switch under the nest) sees that a plate is there, never
which one. The ids that the nests, the hotel pockets and the grippers report come from a reader at
each of them (a fixed-mount barcode reader at every nest and pocket, one in each gripper's palm)
that reads a plate's label once when the plate arrives. A read fails with probability
``failure_rate``; the holder then reports the plate as present without an id until it leaves.

What the robot side makes of an unread plate: a nest reports "occupied, id unknown" (the SiLA
inventory puts the plate at the hand-over nest it was delivered to); a gripper reports no held id;
a hotel pocket's message has no occupancy field apart from the id, so an unread plate in a pocket
reads as an empty pocket and a PutLabware from it is refused (SLOT_EMPTY).

Each read's outcome is drawn from (seed, holder, plate, how many times that plate arrived there), so
it does not depend on when or how often the sensors are polled. Lives on the sim thread.
"""

from __future__ import annotations

import zlib

import numpy as np


class IdentityReaders:
    """One reader per holder name; ``report`` is called with what physics has in the holder."""

    def __init__(self, failure_rate: float = 0.0, seed: int = 0) -> None:
        if not 0.0 <= failure_rate <= 1.0:
            raise ValueError(f"failure_rate must be in 0..1, got {failure_rate}")
        self.failure_rate = failure_rate
        self.seed = seed
        self._present: dict[str, str] = {}  # holder -> the plate there at its last report
        self._read_ok: dict[str, bool] = {}  # holder -> whether that plate's label was read
        self._arrivals: dict[tuple[str, str], int] = {}
        self.failed_reads: list[tuple[str, str]] = []  # (holder, plate), for logs and tests

    def report(self, holder: str, labware_id: str) -> str:
        """The id the holder's reader gives for the plate physically there ("" if none or unread)."""
        if not labware_id:
            self._present.pop(holder, None)
            return ""
        if self._present.get(holder) != labware_id:
            arrival = self._arrivals.get((holder, labware_id), 0) + 1
            self._arrivals[(holder, labware_id)] = arrival
            self._present[holder] = labware_id
            self._read_ok[holder] = self._reads(holder, labware_id, arrival)
            if not self._read_ok[holder]:
                self.failed_reads.append((holder, labware_id))
        return labware_id if self._read_ok[holder] else ""

    def _reads(self, holder: str, labware_id: str, arrival: int) -> bool:
        if self.failure_rate <= 0.0:
            return True
        key = zlib.crc32(f"{holder}/{labware_id}/{arrival}".encode())
        return bool(np.random.default_rng([self.seed, key]).random() >= self.failure_rate)
