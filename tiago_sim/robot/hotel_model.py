"""The onboard hotel (plate holder) of our TIAGo++ model, and the corner brackets its pockets share
with the lab's nests.

Why apart from robot_model: the hotel is our addition to PAL's robot (a tray on a post at the
base front with two pockets), and its bracket geometry serves the scene's nests too. Pure
geometry and URDF text; safe on any thread.
"""

from __future__ import annotations

import math

from tiago_sim.robot.urdf_writer import UrdfWriter

# Hotel (onboard plate holder): pocket floors on the base front, reachable top-down by either arm
HOTEL_SLOT_XYZ = ((0.25, -0.07, 0.60), (0.25, 0.07, 0.60))
HOTEL_POCKET_SIZE = (0.1318, 0.0895)  # inner length x width, 2 mm clearance per side
HOTEL_WALL_HEIGHT = 0.004  # vertical part at the pocket edge; the lead-in chamfer sits on top (rim 10 mm)
HOTEL_LEAD_IN = 0.006  # per side, 45 deg chamfers on the corner posts: a plate carried a few mm off
# centre in the gripper slides into the pocket instead of resting on a post (seed 102 of the campaign)


def corner_bracket_boxes(length: float, width: float, height: float, leg: float = 0.015, wall: float = 0.006):
    """Boxes (size, centre) of four L-brackets framing a pocket of inner size length x width.

    The brackets hold only the corners, so the middle of each long side stays free for finger pads.
    """
    boxes = []
    for cx in (-1, 1):
        for cy in (-1, 1):
            x_edge = cx * (length / 2 + wall / 2)
            y_edge = cy * (width / 2 + wall / 2)
            boxes.append(
                ((wall, leg + wall, height), (x_edge, cy * (width / 2 - leg / 2 + wall / 2), height / 2))
            )
            boxes.append(((leg, wall, height), (cx * (length / 2 - leg / 2), y_edge, height / 2)))
    return boxes


def _corner_brackets(x: float, y: float, z: float, length: float, width: float):
    return [
        ("box", size, (x + cx, y + cy, z + cz), (0, 0, 0), "dark")
        for size, (cx, cy, cz) in corner_bracket_boxes(length, width, HOTEL_WALL_HEIGHT)
    ] + _lead_ins(x, y, z, length, width)


def _lead_ins(
    x: float, y: float, z: float, length: float, width: float, leg: float = 0.015, wall: float = 0.006
):
    """45 deg chamfer plates on top of the corner posts, widening the opening by HOTEL_LEAD_IN per side."""
    lead, thick, top = HOTEL_LEAD_IN, 0.003, z + HOTEL_WALL_HEIGHT
    slope = lead * math.sqrt(2.0)
    inset = thick / 2 / math.sqrt(2.0)  # the plate's lower face meets the wall's top edge
    shapes = []
    for cx in (-1, 1):
        for cy in (-1, 1):
            across = (x + cx * (length / 2 + lead / 2 + inset), y + cy * (width / 2 - leg / 2 + wall / 2))
            shapes.append(
                ("box", (slope, leg + wall, thick), (*across, top + lead / 2 - inset),
                 (0, -math.pi / 4 if cx > 0 else -3 * math.pi / 4, 0), "dark")
            )  # fmt: skip
            along = (x + cx * (length / 2 - leg / 2), y + cy * (width / 2 + lead / 2 + inset))
            shapes.append(
                ("box", (leg, slope, thick), (*along, top + lead / 2 - inset),
                 (math.pi / 4 if cy > 0 else 3 * math.pi / 4, 0, 0), "dark")
            )  # fmt: skip
    return shapes


def add_hotel(w: UrdfWriter, wheel_radius: float) -> None:
    """A post-mounted tray with one pocket (floor + four corner L-posts) per slot, on ``base_link``
    (which stands ``wheel_radius`` above the floor)."""
    length, width = HOTEL_POCKET_SIZE
    shapes = []
    for x, y, z in HOTEL_SLOT_XYZ:
        shapes.append(
            ("box", (length + 0.03, width + 0.02, 0.01), (x, y, z - 0.005 - wheel_radius), (0, 0, 0), "grey")
        )
        shapes.extend(_corner_brackets(x, y, z - wheel_radius, length, width))
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
