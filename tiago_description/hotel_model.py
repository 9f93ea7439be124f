"""The onboard hotel (plate holder) of our TIAGo++ model, and the corner brackets its pockets share
with the lab's nests.

Why apart from robot_model: the hotel is our addition to PAL's robot (a tray on a post at the
base front with two pockets), and its bracket geometry serves the scene's nests too. Pure
geometry and URDF text; safe on any thread.
"""

from __future__ import annotations

import math

from tiago_description.urdf_writer import UrdfWriter

# Hotel (onboard plate holder): pocket floors on the base front, reachable top-down by either arm
HOTEL_SLOT_XYZ = ((0.25, 0.07, 0.60), (0.25, -0.07, 0.60))
HOTEL_POCKET_SIZE = (0.1318, 0.0895)  # inner length x width, 2 mm clearance per side
TRAY_BEYOND_POCKET = (0.03, 0.02)  # m: the tray plate is the pocket plus this along x and across
# Per side, 45 deg ramps rising from the pocket floor at the pocket edge to this far outside it (the
# rim's height too), as the station nests' brackets. The pockets had a 4 mm vertical wall under 6 mm
# chamfers until the default calibration errors (joint offsets, about 1.3 mm median at the hotel) put
# plates at the pocket edge: a plate's end then came to rest on the wall's top corner, 2 deg tilted
# (3 of 6 scripted placements), the failure mode the nests had with a 1.5 mm wall.
HOTEL_LEAD_IN = 0.008
RAMP_FOOT = 0.001  # a ramp runs on this far below the floor it rises from: no edge is left at its foot
RAMP_LEG_LENGTH = 0.015  # bracket legs run this far in from each corner
RAMP_THICKNESS = 0.004


def corner_ramp_boxes(
    length: float, width: float, lead: float, foot: float = RAMP_FOOT, leg: float = RAMP_LEG_LENGTH
) -> list[tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]]:
    """Boxes (size, centre, rpy) of four corner L-brackets of 45 deg lead-in ramps around a pocket.

    The frame is the pocket floor's centre. Each bracket leg is a ramp rising from the pocket edge
    on the floor to ``lead`` outside it, so a plate released up to clearance + lead off centre slides
    into the pocket; with no vertical wall under the ramp there is no ledge for a plate's bottom to
    rest on. The brackets leave the middle of the long sides free for the finger pads.
    """
    boxes = []
    overlap, thick = 0.006, RAMP_THICKNESS
    slope = (lead + foot) * math.sqrt(2.0)
    inset = thick / 2 / math.sqrt(2.0)  # from the ramp surface to the box's mid-plane, along x (or y) and z
    mid = (lead - foot) / 2  # the middle of the ramp surface, outwards of the pocket edge and above the floor
    for cx in (-1, 1):
        for cy in (-1, 1):
            # leg across the short end (ramp rising along x), spanning `leg` in from the corner
            along_y = cy * (width / 2 - leg / 2 + overlap / 2)
            pitch = -math.pi / 4 if cx > 0 else -3 * math.pi / 4
            centre_x = (cx * (length / 2 + mid + inset), along_y, mid - inset)
            boxes.append(((slope, leg + overlap, thick), centre_x, (0.0, pitch, 0.0)))
            # leg along the long side (ramp rising along y)
            along_x = cx * (length / 2 - leg / 2)
            roll = math.pi / 4 if cy > 0 else 3 * math.pi / 4
            centre_y = (along_x, cy * (width / 2 + mid + inset), mid - inset)
            boxes.append(((leg, slope, thick), centre_y, (roll, 0.0, 0.0)))
    return boxes


def _pocket_ramps(x: float, y: float, z: float, length: float, width: float):
    return [
        ("box", size, (x + cx, y + cy, z + cz), rpy, "dark")
        for size, (cx, cy, cz), rpy in corner_ramp_boxes(length, width, HOTEL_LEAD_IN)
    ]


def add_hotel(w: UrdfWriter, wheel_radius: float) -> None:
    """A post-mounted tray with one pocket (floor + four corner L-posts) per slot, on ``base_link``
    (which stands ``wheel_radius`` above the floor)."""
    length, width = HOTEL_POCKET_SIZE
    shapes = []
    for x, y, z in HOTEL_SLOT_XYZ:
        shapes.append(
            (
                "box",
                (length + TRAY_BEYOND_POCKET[0], width + TRAY_BEYOND_POCKET[1], 0.01),
                (x, y, z - 0.005 - wheel_radius),
                (0, 0, 0),
                "grey",
            )
        )
        shapes.extend(_pocket_ramps(x, y, z - wheel_radius, length, width))
    post_top = HOTEL_SLOT_XYZ[0][2] - 0.01 - wheel_radius
    base_top = 0.297 - wheel_radius
    post_height = post_top - base_top
    shapes.append(
        (
            "box",
            (0.04, 0.06, post_height),
            (HOTEL_SLOT_XYZ[0][0], 0, base_top + post_height / 2),
            (0, 0, 0),
            "grey",
        )
    )
    w.link("hotel_link", 1.5, shapes)
    w.joint("hotel_joint", "fixed", "base_link", "hotel_link")
    for index, (x, y, z) in enumerate(HOTEL_SLOT_XYZ, start=1):
        w.link(f"hotel_slot_{index}")
        w.joint(
            f"hotel_slot_{index}_joint", "fixed", "base_link", f"hotel_slot_{index}", (x, y, z - wheel_radius)
        )


def hotel_sweep_radius() -> float:
    """The hotel tray's farthest corner from the base centre (m), the circle it sweeps when the base
    turns: the tray plate is the pocket plus ``TRAY_BEYOND_POCKET`` (``add_hotel``), 0.354 m."""
    length, width = HOTEL_POCKET_SIZE
    return max(
        math.hypot(
            abs(x) + (length + TRAY_BEYOND_POCKET[0]) / 2, abs(y) + (width + TRAY_BEYOND_POCKET[1]) / 2
        )
        for x, y, _ in HOTEL_SLOT_XYZ
    )
