"""Whether closed fingers hold a plate flat, from how far apart they stopped (robot software).

Why: the gripper reports its fingers' opening, and a plate held flat spans its short side between
them; a plate tilted in the hand (seen: 75 mm apart on an 85.5 mm plate, which then fell over in the
hotel) stops them elsewhere. The check needs only the joint readings and the lab's plate sizes.
Pure; any thread.
"""

from __future__ import annotations

GRASP_WIDTH_TOLERANCE_M = 0.004
"""Fingers closed on a plate stand its short side apart; on a plate tilted over 28 deg about its long
side they stand off by more than this."""


def grasp_width_problem(opening_m: float, plate_widths: tuple[float, ...]) -> str:
    """Why fingers closed `opening_m` apart do not hold one of the lab's plates flat ("" if they
    do, or when no widths are known): a plate held flat spans its short side."""
    if not plate_widths:
        return ""
    nearest = min(plate_widths, key=lambda width: abs(width - opening_m))
    if abs(nearest - opening_m) <= GRASP_WIDTH_TOLERANCE_M:
        return ""
    return (
        f"the fingers closed {1000 * opening_m:.1f} mm apart, and no plate of this lab is that wide "
        f"(nearest {1000 * nearest:.1f} mm): the plate is not held flat"
    )
