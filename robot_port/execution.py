"""The handle of something the hardware does over time: a trajectory, a grip, a drive, a dock.

Why a protocol and not a future: a skill reports progress and the time left while it waits, may
cancel halfway (a cancelled drive must stand before the goal ends), and reads why a motion failed
in the robot's own terms (a code of labware_interfaces/msg/ErrorCodes and a sentence).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable


@runtime_checkable
class Execution(Protocol):
    """A running (or finished) command; every member may be read from any thread."""

    name: str

    @property
    def done(self) -> bool:
        """Finished: succeeded, failed or cancelled, and standing still."""

    @property
    def success(self) -> bool:
        """Done and reached its goal."""

    @property
    def error_code(self) -> str:
        """Why it failed (labware_interfaces/msg/ErrorCodes), "" while running or on success."""

    @property
    def message(self) -> str:
        """What happened, in a sentence."""

    @property
    def progress(self) -> float:
        """0..1, never going back."""

    @property
    def phase(self) -> str:
        """What it is doing now, in a word or two."""

    @property
    def remaining_s(self) -> float:
        """Estimated seconds of robot time until done."""

    @property
    def result(self) -> dict[str, Any]:
        """Readings the command ends with (a gripper: ``holding``, ``opening_m``)."""

    def wait(self, timeout_s: float) -> bool:
        """Block until done or ``timeout_s`` (wall) passed; returns ``done``."""

    def cancel(self) -> None:
        """Ask it to stop safely; it is done once it stands."""
