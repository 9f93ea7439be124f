"""The torso and head while the base drives: to the bench height and towards the station's marker on
the way to a station, the torso down elsewhere.

Why: the final approach at a station waited for the torso's 0.17 m rise to the bench posture (2.7 s
at 0.07 m/s) while the base covered its 0.22 m in 1.3 s; the torso set the approach's pace (the time
budget on the benchmarks page, the robot-time issue). A TIAGo++ lifts its torso while its base
drives (separate controllers), so a drive to a station's POI takes the torso to the bench height
beside the drive, and a drive from one station to the next keeps it there. Driving with it up
changes neither the base's footprint nor the tucked arms' sweep across the floor; the arms only
pass higher (from 0.91 m instead of 0.74 m up, over a standing bench's top too).

Why beside the drive and not timed to end with it: the drive's remaining time is read once per
poll of the goal, and an unpaced simulation covers up to 2 s of robot time between two polls, so a
rise timed to the drive's end started late and kept the goal 0.3 to 0.8 s longer than the drive.
It starts once the drive moves, not before: while navigation plans, a moving torso keeps an
unpaced simulation's clock running, which counted the planning's wall time as 0.4 s of robot time.
A drive anywhere else (the dock, a free POI) lowers the torso to the travel height, as before.

The head too: the final approach began by turning the head to the station's marker (0.8 rad of tilt,
about 0.5 s) after the drive had stopped. A drive to a station's POI now turns it beside the drive
to where the marker is seen from the POI with the torso at the bench height (the lab description's
marker, the robot model's head), so the first look needs at most a small correction for where
navigation really stopped. The head camera plays no part in navigation (the laser localises).
Lives on: an rclpy executor thread (inside a navigation goal).
"""

from __future__ import annotations

from collections.abc import Callable

from robot_port.execution import Execution
from tiago_description.motion_library import MotionLibrary
from tiago_skills.goal_run import GoalRun
from tiago_skills.joint_commands import move_joints

TORSO = "torso_lift_joint"
AT_HEIGHT_M = 0.01  # a torso this near its target is left where it stands


def bench_torso_m(motions: MotionLibrary) -> float | None:
    """The torso height of the bench posture ("Benchtop"'s first keyframe that sets it)."""
    return next((frame[TORSO] for frame in motions.keyframes.get("Benchtop", []) if TORSO in frame), None)


def travel_torso_m(motions: MotionLibrary) -> float | None:
    """The torso height of the travel posture ("Travel"'s last keyframe that sets it)."""
    heights = [frame[TORSO] for frame in motions.keyframes.get("Travel", []) if TORSO in frame]
    return heights[-1] if heights else None


class PostureBesideDrive:
    """The moves of joint `groups` (the torso, the head) beside one drive, started once the drive moves
    (`poll`); each group its own move, so the head is not held to the torso's 0.07 m/s."""

    def __init__(self, run: GoalRun, groups: list[dict[str, float]], speed_scale: float) -> None:
        self.run, self.groups, self.speed_scale = run, groups, speed_scale
        self.executions: list[Execution] = []

    def poll(self, drive: Execution) -> None:
        """Called while the drive runs: start the moves once the drive has a plan and moves."""
        if not self.executions and float(drive.remaining_s) > 0.0:
            self.start()

    def start(self) -> None:
        if not self.executions:
            self.executions = [self.run.read(move_joints(group, self.speed_scale)) for group in self.groups]

    def finish(self) -> None:
        """After the drive: follow the moves to their end (started now if the drive never moved)."""
        self.start()
        for execution in self.executions:
            self.run.follow(execution, span=(1.0, 1.0))


def posture_for_drive(
    run: GoalRun,
    motions: MotionLibrary,
    speed_scale: float,
    to_station: bool,
    head_at_station: Callable[[float], dict[str, float]] | None = None,
) -> PostureBesideDrive | None:
    """The torso's (and on the way to a station, the head's) moves beside a drive to a station's POI
    (`to_station`) or elsewhere; `head_at_station(torso_m)` aims the head from the POI. None: all
    stay (already there, or a low torso on the way elsewhere)."""
    target = bench_torso_m(motions) if to_station else travel_torso_m(motions)
    height = run.read(lambda hardware: hardware.joint_positions()[TORSO])
    groups = []
    if target is not None and not (
        abs(height - target) <= AT_HEIGHT_M or (not to_station and height < target)
    ):
        groups.append({TORSO: target})
    if to_station and head_at_station is not None:
        groups.append(head_at_station(height if target is None else target))
    return PostureBesideDrive(run, groups, speed_scale * motions.speed_scale) if groups else None
