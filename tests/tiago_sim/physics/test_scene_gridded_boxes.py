"""Static boxes (floor, walls, benches, boards, dock) are seen as gridded meshes and built front to
back, both only to render faster: the head camera must see exactly what plain boxes drawn in any
order show. Checked at the start pose and looking at every station's marker from its POI, in the
default lab and a random one."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest

from lab_description.world import World, load_world
from lab_description.world_schema import SCHEMA_FILE
from tiago_sim.layouts.generator import layout_world
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd
from tiago_sim.physics.simulation import Simulation

EYE_HEIGHT = 1.25  # m: about the head camera's height over a POI


def _views(sim: Simulation, world: World) -> list[np.ndarray]:
    views = [sim.true_camera_pose()]
    for station in world.stations:
        poi = world.pois[station.poi]
        target = station.T_world_marker()[:3, 3]
        views.append(optical_frame_looking_at(np.array([poi.x, poi.y, EYE_HEIGHT]), target))
    return views


def _replace_with_plain_boxes(sim: Simulation) -> int:
    """Every gridded static body moved far away, a plain box of its size and colour put in its place
    (created last, so drawn after everything: the other order)."""
    client, scene = sim.client_id, sim.scene
    replaced = 0
    for body in [
        scene.floor,
        scene.dock,
        *scene.walls.values(),
        *scene.tables.values(),
        *scene.marker_stands.values(),
    ]:
        shape = p.getVisualShapeData(body, physicsClientId=client)[0]
        if shape[2] != p.GEOM_MESH:
            continue
        size = p.getCollisionShapeData(body, -1, physicsClientId=client)[0][3]
        position, orientation = p.getBasePositionAndOrientation(body, physicsClientId=client)
        p.resetBasePositionAndOrientation(body, [0, 0, -500], orientation, physicsClientId=client)
        visual = p.createVisualShape(
            p.GEOM_BOX, halfExtents=[s / 2 for s in size], rgbaColor=shape[7], physicsClientId=client
        )
        p.createMultiBody(0.0, -1, visual, position, orientation, physicsClientId=client)
        replaced += 1
    return replaced


@pytest.mark.parametrize("lab", ["default", "random layout 75083"])
def test_gridded_boxes_drawn_front_to_back_render_the_pixels_of_plain_boxes(lab: str) -> None:
    world = load_world(SCHEMA_FILE.parent / "default.yaml") if lab == "default" else layout_world(75083)
    sim = Simulation(world, seed=1)
    intrinsics = CameraIntrinsics()
    try:
        views = _views(sim, world)
        before = [render_rgbd(sim.client_id, view, intrinsics) for view in views]
        walls_floor_benches = 4 + 1 + len(world.stations)
        assert _replace_with_plain_boxes(sim) >= walls_floor_benches
        after = [render_rgbd(sim.client_id, view, intrinsics) for view in views]
    finally:
        sim.close()
    for (rgb, depth), (box_rgb, box_depth) in zip(before, after, strict=True):
        assert (depth < 0.99 * intrinsics.far).mean() > 0.3  # much of the view is the lab
        assert np.array_equal(rgb, box_rgb)
        # depth to float rounding (the triangles interpolate it from other corners): 0.02 mm at 2.6 m
        assert np.allclose(depth, box_depth, rtol=2e-5, atol=0.0)


def test_a_gridded_face_is_cut_into_squares_no_larger_than_a_cell() -> None:
    from tiago_sim.physics.gridded_box import GRID_CELL, _face

    vertices, normals, indices = _face([5.0, 0.05, 0.5], axis=1, sign=-1, cell=GRID_CELL)
    points = np.array(vertices)
    assert {tuple(n) for n in normals} == {(0.0, -1.0, 0.0)}
    assert np.allclose(points[:, 1], -0.05)
    triangles = points[np.array(indices).reshape(-1, 3)]
    spans = triangles.max(axis=1) - triangles.min(axis=1)
    assert spans.max() <= GRID_CELL + 1e-9
    # counter-clockwise seen from outside: every triangle's normal points along the face's
    normals_out = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    assert (normals_out[:, 1] < 0).all()
    assert len(indices) // 3 == 2 * 20 * 2  # 10 m by 1 m in 0.5 m squares
