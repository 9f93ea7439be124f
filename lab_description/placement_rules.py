"""The rules a world file's stations are placed and checked by, in words, with the numbers the code
uses: `python -m lab_description.placement_rules` prints them (the docs include its output).

Why a command: the docs stated rules by hand ("the bench edge 0.36 .. 0.45 m ahead") that disagreed
with the loader (0.37 m). Every number here is read from the constants `station_placement` and
`serviceability` decide with.
"""

from __future__ import annotations

import sys

from lab_description import serviceability as service
from lab_description import station_placement as placement
from tiago_description import robot_model as rm


def rules() -> list[str]:
    """Each rule as one line of Markdown."""
    band = rm.TOP_DOWN_REACH_BAND_M
    working = f"{service.WORKING_CLEARANCE:.3f} m"
    tray = f"{service.HOTEL_SWEEP_RADIUS:.3f} m"
    base = f"{service.BASE_RADIUS:.3f} m"
    undock = f"{service.BASE_RADIUS + service.TURN_MARGIN:.3f} m"
    turning = f"{service.HOTEL_SWEEP_RADIUS + service.TURN_MARGIN:.3f} m"
    near, far = service.MARKER_DISTANCE_RANGE
    torso_low, torso_high = rm.TORSO_LIFT_RANGE
    return [
        "**Where the robot works** (chosen unless the file sets `poi.work_standoff`): the nearest "
        f"distance in front of the nest row that keeps the bench's front edge {working} ahead of the "
        f"base (the hotel tray's turning circle, {tray}, plus where the marker-guided final approach "
        "may end) and from which the head camera sees the marker; up to "
        f"{placement.VIEW_BACKOFF_M:.2f} m farther back for the view.",
        f"**Where navigation stops** (`poi.standoff`): {placement.FINAL_APPROACH_M:.2f} m behind the "
        "working pose; the final approach drives the rest, guided by the marker.",
        f"**Sideways** (`poi.lateral`): the row's middle {band / 2:.3f} m to the right of the base, the "
        f"middle of the right arm's {band:.2f} m band; a nest less than {placement.ARM_SIDE_MARGIN_M:.2f} m "
        "inside the band is worked at from a pose moved along the bench (a row longer than the band "
        "is served that way).",
        f"**Approach height** (`nests.approach_height`): {placement.PREFERRED_APPROACH_HEIGHT_M:.2f} m "
        f"above the nest, lowered in {placement.APPROACH_HEIGHT_STEP_M * 100:.0f} cm steps where the "
        "arm cannot reach that high, then to the least: the tallest labware type plus "
        f"{placement.APPROACH_CLEARANCE_M:.2f} m, never lower.",
        "**Refused: a nest out of reach**: from the pose it is worked at from, no torso height "
        f"({torso_low:g} to {torso_high:g} m) and right-arm pose puts the gripper top-down on it, at the "
        "grasp and at the approach height; the message says how high the arm reaches there.",
        f"**Refused: no room for the base**: the base disc (radius {base}) at the docked pose, and "
        f"{working} at every working pose, clear every bench; along the straight undock the base disc "
        f"plus the navigation error ({undock}); at every station POI and the dock's POI the tray's "
        f"turning circle plus the navigation stop error ({turning}); the base disc plus the "
        f"navigation error ({undock}) clear of the dock along every drive of the final approach "
        "(from the POI to each working pose, and between the working poses).",
        "**Refused: a marker out of view**: from the POI and every working pose the head camera, aimed "
        f"at the marker, sees it {near:g} to {far:g} m away, at most "
        f"{service.MARKER_MAX_OBLIQUITY_DEG:g} deg off its face's normal and at least "
        f"{service.MARKER_MIN_PIXELS:g} px wide, within the head's pan and tilt limits.",
    ]


def main() -> int:
    sys.stdout.write("".join(f"- {rule}\n" for rule in rules()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
