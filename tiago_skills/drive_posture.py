"""The torso while the base drives: down to the travel height, or up to the bench's as it reaches a station.

Why: the final approach at a station waited for the torso's 0.17 m rise to the bench posture (2.7 s
at 0.07 m/s) while the base covered its 0.22 m in 1.3 s; the torso set the approach's pace (the
time budget on the benchmarks page, the robot-time issue). A real TIAGo++ lifts its torso while its
base drives (separate controllers), so a drive to a station's POI now brings the torso to the bench
height as the base arrives: the rise starts when the drive's own remaining time falls to the rise's
duration, and a torso already there (a drive from one station to the next) stays. A drive anywhere
else lowers it to the travel height at once, as before. Lives on: an rclpy executor thread (inside
a navigation goal).
"""

from __future__ import annotations

from dataclasses import dataclass

from robot_port.execution import Execution
from robot_port.trajectory_timing import RAMP_S, trapezoid_duration
from tiago_description.motion_library import MotionLibrary
from tiago_description.robot_limits import active_limits
from tiago_skills.goal_run import GoalRun
from tiago_skills.joint_commands import move_joints

TORSO = "torso_lift_joint"
AT_HEIGHT_M = 0.01  # a torso this near its target is left where it stands
LEAD_MARGIN_S = 0.5
"""The rise starts this much earlier than its own duration before the drive's end: the drive's remaining
time is read once per poll and runs a little short near the goal, and a torso still rising after the
base stood kept the goal 0.4 s longer (seed 1, default lab); standing a moment early costs nothing."""


def bench_torso_m(motions: MotionLibrary) -> float | None:
    """The torso height of the bench posture ("Benchtop"'s first keyframe that sets it)."""
    return next((frame[TORSO] for frame in motions.keyframes.get("Benchtop", []) if TORSO in frame), None)


def travel_torso_m(motions: MotionLibrary) -> float | None:
    """The torso height of the travel posture ("Travel"'s last keyframe that sets it)."""
    heights = [frame[TORSO] for frame in motions.keyframes.get("Travel", []) if TORSO in frame]
    return heights[-1] if heights else None


@dataclass
class TorsoDuringDrive:
    """The torso's move beside one drive: started at once, or when the drive's remaining time falls to
    `lead_s` (None: not at all)."""

    run: GoalRun
    target_m: float
    speed_scale: float
    lead_s: float | None
    execution: Execution | None = None

    def start(self) -> None:
        if self.execution is None:
            self.execution = self.run.read(move_joints({TORSO: self.target_m}, self.speed_scale))

    def poll(self, drive: Execution) -> None:
        """Called while the drive runs: start the rise once it would end as the base arrives."""
        if self.lead_s is not None and float(drive.remaining_s) <= self.lead_s:
            self.start()

    def finish(self) -> None:
        """After the drive: a rise not yet started starts now; follow the move to its end."""
        self.start()
        assert self.execution is not None
        self.run.follow(self.execution, span=(1.0, 1.0))


def torso_for_drive(
    run: GoalRun, motions: MotionLibrary, speed_scale: float, to_station: bool
) -> TorsoDuringDrive | None:
    """What the torso does during a drive to a station's POI (`to_station`) or elsewhere; None: nothing."""
    target = bench_torso_m(motions) if to_station else travel_torso_m(motions)
    if target is None:
        return None
    height = run.read(lambda hardware: hardware.joint_positions()[TORSO])
    if abs(height - target) <= AT_HEIGHT_M or (not to_station and height < target):
        return None  # there already; a low torso is not raised for travel
    scale = speed_scale * motions.speed_scale
    posture = TorsoDuringDrive(run, target, scale, None)
    if to_station and height < target:  # rise as the base arrives
        rise_s = trapezoid_duration((target - height) / (active_limits().torso_speed * scale), RAMP_S)
        posture.lead_s = rise_s + LEAD_MARGIN_S
    else:
        posture.start()
    return posture
