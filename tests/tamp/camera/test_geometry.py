"""Pinhole geometry without a simulator: projection and back-projection invert each other."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tamp.camera.geometry import backproject, camera_pose, intrinsics, project
from tamp.sim.base import Camera

CAMERAS = (
    Camera(),
    Camera(eye=(0.9, 0.5, 0.6), target=(0.4, -0.1, 0.05), fovy=55.0, width=160, height=120),
    Camera(eye=(0.5, 0.0, 1.2), target=(0.52, 0.01, 0.0), up=(1.0, 0.0, 0.0), width=64, height=96),
)


@pytest.mark.parametrize("camera", CAMERAS)
def test_backprojected_pixels_project_back_onto_themselves(camera):
    rng = np.random.default_rng(0)
    depth = rng.uniform(0.3, 2.5, (camera.height, camera.width))
    points = backproject(depth, camera)  # (H, W, 3)
    uv, z = project(points, camera)
    v, u = np.mgrid[0 : camera.height, 0 : camera.width]
    np.testing.assert_allclose(uv[..., 0], u, atol=1e-8)
    np.testing.assert_allclose(uv[..., 1], v, atol=1e-8)
    np.testing.assert_allclose(z, depth, rtol=1e-12)


@pytest.mark.parametrize("camera", CAMERAS)
def test_a_projected_world_point_comes_back_from_its_pixel(camera):
    rng = np.random.default_rng(1)
    k = intrinsics(camera)
    pose = camera_pose(camera)
    for _ in range(20):  # points on pixel centres at random depths, built in the camera frame
        u, v = rng.integers(0, camera.width), rng.integers(0, camera.height)
        z = rng.uniform(0.2, 2.0)
        local = np.array([(u - k[0, 2]) / k[0, 0] * z, (v - k[1, 2]) / k[1, 1] * z, z])
        world = pose[:3, :3] @ local + pose[:3, 3]
        uv, depth_here = project(world, camera)
        np.testing.assert_allclose(uv, (u, v), atol=1e-8)
        image = np.full((camera.height, camera.width), 1.0)
        image[v, u] = depth_here
        np.testing.assert_allclose(backproject(image, camera)[v, u], world, atol=1e-12)


def test_camera_frame_axes_and_field_of_view():
    camera = Camera()
    pose = camera_pose(camera)
    np.testing.assert_allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(pose[:3, :3]) == pytest.approx(1.0)
    target = np.asarray(camera.target)
    uv, z = project(target, camera)  # the optical axis hits the principal point
    np.testing.assert_allclose(uv, ((camera.width - 1) / 2, (camera.height - 1) / 2), atol=1e-9)
    assert z == pytest.approx(np.linalg.norm(target - np.asarray(camera.eye)))
    (_, v_up), _ = project(target + np.array([0.0, 0.0, 0.05]), camera)  # higher is up in the image
    assert v_up < (camera.height - 1) / 2
    # a ray fovy/2 above the axis meets the top edge of the image (v = -1/2)
    forward, down = pose[:3, 2], pose[:3, 1]
    half = math.radians(camera.fovy) / 2
    edge = pose[:3, 3] + forward * math.cos(half) - down * math.sin(half)
    (_, v_edge), _ = project(edge, camera)
    assert v_edge == pytest.approx(-0.5)


def test_bad_depth_shape_and_degenerate_up_are_named():
    with pytest.raises(ValueError, match="does not fit a 320x240 camera"):
        backproject(np.ones((10, 10)), Camera())
    with pytest.raises(ValueError, match="parallel to its line of sight"):
        camera_pose(Camera(eye=(0.0, 0.0, 1.0), target=(0.0, 0.0, 0.0)))
