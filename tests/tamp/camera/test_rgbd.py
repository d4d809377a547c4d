"""Depth images of both simulators: z-depth in metres that back-projects onto the scene."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.camera.geometry import backproject, project
from tamp.scene import Pose
from tamp.sim import SIMULATORS, make_simulator

pytestmark = pytest.mark.sim

POSES = {"a": Pose((0.5, 0.0, 0.025), 0.3), "b": Pose((0.42, -0.22, 0.075), -0.2)}


@pytest.fixture(scope="module", params=SIMULATORS)
def view(request):
    """(simulator name, RGB, depth, world points) of two blocks, one of them in mid-air."""
    with make_simulator(request.param, tuple(POSES), POSES) as sim:
        rgb, depth = sim.render_rgbd()
        assert np.array_equal(rgb, sim.render())  # the same image as render()
        yield request.param, rgb, depth, backproject(depth, sim.camera), sim.camera


def test_depth_is_metric_float32_of_the_image_size(view):
    _, rgb, depth, _, camera = view
    assert rgb.shape == (camera.height, camera.width, 3) and rgb.dtype == np.uint8
    assert depth.shape == (camera.height, camera.width) and depth.dtype == np.float32
    assert float(depth.min()) > 0.5 and float(depth.max()) < 3.01  # eye ~1 m above the blocks


@pytest.mark.parametrize("block", sorted(POSES))
def test_the_top_face_centre_pixel_lands_on_the_top_face_centre(view, block):
    sim, rgb, _, points, camera = view
    x, y, z = POSES[block].xyz
    top = np.array([x, y, z + 0.025])
    uv, _ = project(top, camera)
    u, v = np.round(uv).astype(int)
    seen = points[v, u]
    assert abs(seen[2] - top[2]) < 0.001, (sim, seen, top)  # on the face's plane
    assert np.linalg.norm(seen[:2] - top[:2]) < 0.003, (sim, seen, top)  # within the pixel
    assert rgb[v, u].max() > 150  # and the pixel shows the block's colour


def test_the_table_is_the_plane_z_0_across_the_image(view):
    """Off-axis pixels tell z-depth from ray length: at the image corners the ray is about 17%
    longer than the z-depth, so reading ray lengths as z-depths would sink the table there."""
    sim, rgb, _, points, camera = view
    grey = (rgb.max(-1) - rgb.min(-1) < 8) & (rgb.max(-1) < 160)  # (H, W) table, not robot
    corners = [(camera.height - 3, 2), (camera.height - 3, camera.width - 3)]
    for v, u in corners:
        assert grey[v, u], (sim, v, u)
        assert abs(points[v, u, 2]) < 0.0015, (sim, v, u, points[v, u])  # PyBullet's is 1 mm up
    on_table = np.abs(points[..., 2][grey]) < 0.0015  # grey also has the robot's shadows
    assert on_table.sum() > 0.3 * grey.size and on_table.mean() > 0.9, (sim, on_table.mean())
