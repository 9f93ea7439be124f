"""Where a plate can be: a station's nest, a hotel slot, the gripper; or off every holder.

Why one module: the inventory (SiLA side), the physics' ground truth (simulation side) and the
messages between them name these places, and each used to spell them its own way. Here each
place has one type, and a `Location` has one text form, written and read in this module only.

Two text forms, for two readers:
- ``str()`` is for people: ``str(Nest("station_a", 1))`` is "station_a/1" (the standard's
  hand-over position and its sub-position), as error messages show it;
- `location_text` is the machine form that the CheckPlacement service carries and that the
  inventory logs: "station:station_a:1", "hotel:2", "gripper", "floor", "unknown";
  `parse_location` reads it back.

Indices count from 1, as the standard's SubPosition and InternalPosition do. Frozen; safe on any
thread.
"""

from __future__ import annotations

import re
from dataclasses import dataclass


def _check_index(value: object, what: str) -> None:
    """A 1-based index: an int (not a bool) of at least 1."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{what} must be an integer, got {value!r}")
    if value < 1:
        raise ValueError(f"{what} counts from 1, got {value}")


@dataclass(frozen=True, order=True)
class Nest:
    """One nest of a station: the station's name (the standard's hand-over position) and the
    nest's 1-based sub-position. Nests sort by station name, then sub-position."""

    station: str
    sub_position: int

    def __post_init__(self) -> None:
        if not isinstance(self.station, str) or not self.station:
            raise ValueError(f"a nest needs a station name, got {self.station!r}")
        _check_index(self.sub_position, f"the sub-position of a nest of {self.station!r}")

    def __str__(self) -> str:
        return f"{self.station}/{self.sub_position}"


@dataclass(frozen=True, order=True)
class HotelSlot:
    """One pocket of the robot's onboard hotel (the standard's InternalPosition), 1-based."""

    index: int

    def __post_init__(self) -> None:
        _check_index(self.index, "a hotel slot index")

    def __str__(self) -> str:
        return f"hotel slot {self.index}"


@dataclass(frozen=True)
class Gripper:
    """Between the fingers of the robot's gripper (whichever arm: no layer tells them apart)."""

    def __str__(self) -> str:
        return location_text(self)


@dataclass(frozen=True)
class Floor:
    """Off every holder, lying on the floor; only the physics' ground truth can tell this."""

    def __str__(self) -> str:
        return location_text(self)


@dataclass(frozen=True)
class Unknown:
    """Nowhere the observations can say: no sensor and no robot report shows the plate."""

    def __str__(self) -> str:
        return location_text(self)


GRIPPER = Gripper()
FLOOR = Floor()
UNKNOWN = Unknown()

Location = Nest | HotelSlot | Gripper | Floor | Unknown
"""Anywhere a plate can be. The inventory uses all but `Floor`; the physics' check all of them."""


def aboard(location: Location) -> bool:
    """True in a hotel slot or the gripper: the plate travels with the robot."""
    return isinstance(location, (HotelSlot, Gripper))


# The text form, in one place: location_text writes it, parse_location reads it.
_STATION_PREFIX = "station:"
_HOTEL_PREFIX = "hotel:"
_WORDS: dict[str, Gripper | Floor | Unknown] = {"gripper": GRIPPER, "floor": FLOOR, "unknown": UNKNOWN}
_WORD_OF = {location: word for word, location in _WORDS.items()}
_INDEX = re.compile(r"[1-9][0-9]*")


def location_text(location: Location) -> str:
    """The machine text of a location: "station:NAME:N", "hotel:N", "gripper", "floor", "unknown"."""
    if isinstance(location, Nest):
        return f"{_STATION_PREFIX}{location.station}:{location.sub_position}"
    if isinstance(location, HotelSlot):
        return f"{_HOTEL_PREFIX}{location.index}"
    if isinstance(location, (Gripper, Floor, Unknown)):
        return _WORD_OF[location]
    raise TypeError(f"not a location: {location!r}")


def parse_location(text: str) -> Location:
    """The location that `location_text` wrote as `text`; raises ValueError for any other text.

    A station name may itself contain ":" (the sub-position is what follows the last one)."""
    if text in _WORDS:
        return _WORDS[text]
    if text.startswith(_HOTEL_PREFIX):
        index = text[len(_HOTEL_PREFIX) :]
        if _INDEX.fullmatch(index):
            return HotelSlot(int(index))
    elif text.startswith(_STATION_PREFIX):
        station, _, sub_position = text[len(_STATION_PREFIX) :].rpartition(":")
        if station and _INDEX.fullmatch(sub_position):
            return Nest(station, int(sub_position))
    raise ValueError(f"not a location: {text!r}; expected station:NAME:N, hotel:N, gripper, floor or unknown")
