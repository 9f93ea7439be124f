"""Why a campaign's trial failed, as one cause of the success table, from what it reported.

Why apart from the campaign: the cause names are the table's columns and the failure messages'
vocabulary (the robot side's error codes, the physics checks' prefixes); the demo's tests and the
campaign's share them. Pure.
"""

from __future__ import annotations

from sila_labware.deployment.demo import DISTURBED, MISPLACED, DemoReport

CAUSES = ("positioning", "perception", "grasp", "navigation", "collision", "other")
# Robot-side error codes (labware_interfaces/msg/ErrorCodes) -> failure cause of the success table;
# COLLISION first: an unintended contact is a collision whatever the step (the plate may still arrive).
CAUSE_BY_ERROR_CODE = {
    "COLLISION": "collision",
    "NAVIGATION_FAILED": "navigation",
    "DOCKED": "navigation",
    "MARKER_NOT_FOUND": "perception",
    "NEST_NOT_SEEN": "perception",
    "GRASP_FAILED": "grasp",
    "PLATE_SLIPPED": "grasp",
    "SLOT_EMPTY": "grasp",  # the plate the robot thought it had stowed is not on board
    "IK_FAILED": "positioning",
    "PLACE_FAILED": "positioning",
    "NEST_OCCUPIED": "positioning",
}
BASE_MOTION_WORDS = ("driving to", "Dock", "Undock")


def classify_failure(report: DemoReport) -> str:
    """Failure cause of one trial from what the SiLA commands and the placement check said."""
    error = report.error
    if error.startswith(DISTURBED):  # another plate knocked out of place: an unintended contact
        return "collision"
    if error.startswith(MISPLACED):  # the commands succeeded, the physics check disagrees
        return "positioning"
    for code, cause in CAUSE_BY_ERROR_CODE.items():
        if code in error:
            return cause
    if "MOTION_FAILED" in error:
        return "navigation" if any(word in error for word in BASE_MOTION_WORDS) else "positioning"
    if any(word in error for word in BASE_MOTION_WORDS):
        return "navigation"
    return "other"
