"""Labware types (sizes and mass, in one place) and plates (one piece of labware and its type).

Why here: the world file defines the types, the physics builds plates and nests from their sizes,
and the SiLA side passes type names through; all of them mean the same `LabwareType`. SI units:
metres and kilograms. Frozen; safe on any thread.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class LabwareType:
    """A kind of labware, for instance an SBS 96-well microplate.

    `length` is the long side and `width` the short side (the gripper closes across the width),
    `height` the outer height, all in metres; `mass` in kilograms. Every size must be positive.
    """

    name: str
    length: float
    width: float
    height: float
    mass: float

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a labware type needs a name, got {self.name!r}")
        for field_name in ("length", "width", "height", "mass"):
            value = getattr(self, field_name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"labware type {self.name!r}: {field_name} must be a number, got {value!r}")
            if value <= 0:
                raise ValueError(f"labware type {self.name!r}: {field_name} must be positive, got {value}")


@dataclass(frozen=True)
class Plate:
    """One piece of labware: its LabwareUniqueID and the name of its `LabwareType`.

    The type name may be empty: schedulers may send plates of unknown type, and the robot then
    tracks them by id alone.
    """

    labware_id: str
    labware_type: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.labware_id, str) or not self.labware_id:
            raise ValueError(f"a plate needs a labware id, got {self.labware_id!r}")
        if not isinstance(self.labware_type, str):
            raise ValueError(f"plate {self.labware_id!r}: type name {self.labware_type!r} is not text")
