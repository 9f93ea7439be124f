"""Scan matching and the localiser on a synthetic room: fast, exact arithmetic, no physics.

The room is 6 x 4 m with a 1 x 0.6 m bench in it, drawn at 1 cm; a scan is made of points on
its surfaces as seen from a true pose, expressed in the base frame.
"""

from __future__ import annotations

import math

import numpy as np

from tiago_description.transforms import compose_planar, invert_planar
from tiago_sim.navigation.likelihood_field import LikelihoodField
from tiago_sim.navigation.localiser import Localiser
from tiago_sim.navigation.occupancy_map import Footprint, OccupancyMap
from tiago_sim.navigation.scan_matcher import match_scan

RESOLUTION = 0.01
TRUE_POSE = (1.0, 0.5, math.radians(20.0))


def room_map(with_walls: bool = True) -> OccupancyMap:
    cells_x, cells_y = int(6 / RESOLUTION), int(4 / RESOLUTION)
    grid = np.zeros((cells_y, cells_x), dtype=bool)
    if with_walls:
        grid[:10, :] = grid[-10:, :] = grid[:, :10] = grid[:, -10:] = True  # 10 cm walls
    empty = OccupancyMap(RESOLUTION, (-3.0, -2.0), grid)
    return empty.with_footprints([Footprint(1.5, -1.0, 0.0, 1.0, 0.6)])


def surface_points(with_walls: bool = True) -> np.ndarray:
    """World points on the room's inner wall faces and the bench's faces (5 cm apart)."""
    points = []
    if with_walls:
        xs, ys = np.arange(-2.85, 2.9, 0.05), np.arange(-1.85, 1.9, 0.05)
        points += [(x, 1.9) for x in xs] + [(x, -1.9) for x in xs]
        points += [(2.9, y) for y in ys] + [(-2.9, y) for y in ys]
    bench_x, bench_y = np.arange(1.0, 2.01, 0.05), np.arange(-1.3, -0.69, 0.05)
    points += [(x, -0.7) for x in bench_x] + [(1.0, y) for y in bench_y]
    return np.array(points)


def in_base(world_points: np.ndarray, pose) -> np.ndarray:
    x, y, yaw = invert_planar(pose)
    c, s = math.cos(yaw), math.sin(yaw)
    return world_points @ np.array([[c, s], [-s, c]]) + np.array([x, y])


def pose_error(pose, truth) -> tuple[float, float]:
    return math.hypot(pose[0] - truth[0], pose[1] - truth[1]), abs(
        math.remainder(pose[2] - truth[2], math.tau)
    )


def test_a_scan_pulls_a_pose_5_cm_and_2_deg_off_back_onto_the_map():
    field = LikelihoodField(room_map())
    rng = np.random.default_rng(1)
    points = in_base(surface_points(), TRUE_POSE)
    points += 0.02 * rng.standard_normal(points.shape)  # the laser's range noise, roughly
    prior = (TRUE_POSE[0] + 0.05, TRUE_POSE[1] - 0.04, TRUE_POSE[2] + math.radians(2.0))
    match = match_scan(field, points, prior, np.diag([0.1**2, 0.1**2, 0.05**2]), 0.02)
    position, yaw = pose_error(match.pose, TRUE_POSE)
    assert position < 0.005 and yaw < math.radians(0.1), (position, math.degrees(yaw))
    assert match.inliers == len(points)


def test_things_not_on_the_map_are_left_out_of_the_match():
    field = LikelihoodField(room_map())
    rng = np.random.default_rng(2)
    on_map = surface_points()
    # a third as many endpoints again on a cart and a person standing in the room, unmapped
    cart = np.column_stack([np.full(60, -1.0), np.linspace(-0.5, 0.5, 60)])
    person = np.column_stack(
        [0.2 + 0.15 * np.cos(np.linspace(0, 3, 40)), 1.0 + 0.15 * np.sin(np.linspace(0, 3, 40))]
    )
    points = in_base(np.vstack([on_map, cart, person]), TRUE_POSE) + 0.02 * rng.standard_normal(
        (len(on_map) + 100, 2)
    )
    prior = (TRUE_POSE[0] - 0.03, TRUE_POSE[1] + 0.03, TRUE_POSE[2] - math.radians(1.0))
    match = match_scan(field, points, prior, np.diag([0.1**2, 0.1**2, 0.05**2]), 0.02)
    position, yaw = pose_error(match.pose, TRUE_POSE)
    assert position < 0.01 and yaw < math.radians(0.2), (position, math.degrees(yaw))
    assert match.inliers <= len(on_map) + 5  # the cart and the person were dropped


def test_a_direction_the_scan_cannot_see_stays_where_odometry_put_it():
    """Only the bench's long face in view: it fixes y and the heading, not x along the face."""
    field = LikelihoodField(room_map(with_walls=False))
    face = np.array([(x, -0.7) for x in np.arange(1.1, 1.91, 0.02)])
    truth = (1.5, 0.3, 0.0)
    prior = (1.55, 0.33, 0.0)
    match = match_scan(field, in_base(face, truth), prior, np.diag([0.05**2, 0.05**2, 0.02**2]), 0.02)
    assert abs(match.pose[1] - truth[1]) < 0.01  # across the face: corrected (outline within 5 mm)
    assert abs(match.pose[0] - prior[0]) < 0.01  # along it: the prediction stands
    assert match.covariance[0, 0] > 10 * match.covariance[1, 1]  # and the covariance says so


def test_localiser_follows_odometry_between_scans_and_drops_a_scan_that_sees_too_little():
    field = LikelihoodField(room_map())
    localiser = Localiser(field, TRUE_POSE, (0.0, 0.0, 0.0))
    # the base drives 0.5 m ahead; odometry reports 0.52 m (wheel slip)
    truth = compose_planar(TRUE_POSE, (0.5, 0.0, 0.0))
    update = localiser.update((0.52, 0.0, 0.0), in_base(surface_points(), truth))
    assert update.accepted, update.reason
    assert pose_error(update.pose, truth)[0] < 0.003
    # map_from_odom turns the odometry of that instant into the localised pose
    assert pose_error(compose_planar(update.map_from_odom, (0.52, 0.0, 0.0)), update.pose)[0] < 1e-9
    few = in_base(surface_points()[:10], truth)
    dropped = localiser.update((0.52, 0.0, 0.0), few)
    assert not dropped.accepted and "fewer than" in dropped.reason
    assert pose_error(dropped.pose, update.pose)[0] < 1e-6  # odometry alone carried on
