"""Pinhole geometry of a `tamp.sim.base.Camera`: intrinsics, pose, projection, back-projection.

Conventions (the same for both simulators, whose cameras take a vertical field of view and
square pixels):

- camera frame: OpenCV axes, x right, y down, z forward along the optical axis (eye -> target);
- pixel coordinates (u, v): u the column, v the row, with the centre of pixel ``image[v, u]``
  at integer (u, v), so the principal point is ((W - 1) / 2, (H - 1) / 2);
- depth: z-depth, the distance along the optical axis (what `Simulator.render_rgbd` gives),
  not the length of the ray through the pixel.

Numpy only: nothing here renders or imports a simulator.
"""

from __future__ import annotations

import math

import numpy as np

from tamp.sim.base import Camera


def intrinsics(camera: Camera) -> np.ndarray:
    """The 3x3 matrix K = [[f, 0, cx], [0, f, cy], [0, 0, 1]], f = (H / 2) / tan(fovy / 2)."""
    f = 0.5 * camera.height / math.tan(math.radians(camera.fovy) / 2)
    return np.array(
        [[f, 0.0, (camera.width - 1) / 2], [0.0, f, (camera.height - 1) / 2], [0.0, 0.0, 1.0]]
    )


def camera_pose(camera: Camera) -> np.ndarray:
    """The 4x4 camera-to-world transform: columns right, down, forward and the eye."""
    eye = np.asarray(camera.eye, dtype=float)
    forward = np.asarray(camera.target, dtype=float) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.up, dtype=float))
    norm = np.linalg.norm(right)
    if norm < 1e-9:
        raise ValueError(f"camera up {camera.up} is parallel to its line of sight")
    right /= norm
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([right, np.cross(forward, right), forward])
    pose[:3, 3] = eye
    return pose


def project(points: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """World points (..., 3) -> pixel coordinates (..., 2) as (u, v) and z-depths (...)."""
    pose = camera_pose(camera)
    local = (np.asarray(points, dtype=float) - pose[:3, 3]) @ pose[:3, :3]  # (..., 3) camera
    z = local[..., 2]
    uvw = local @ intrinsics(camera).T  # (..., 3)
    return uvw[..., :2] / z[..., None], z


def backproject(depth: np.ndarray, camera: Camera) -> np.ndarray:
    """World points (H, W, 3) of a z-depth image (H, W): pixel (u, v) seen at its depth."""
    depth = np.asarray(depth, dtype=float)
    if depth.shape != (camera.height, camera.width):
        raise ValueError(
            f"depth of shape {depth.shape} does not fit a {camera.width}x{camera.height} camera"
        )
    k = intrinsics(camera)
    v, u = np.mgrid[0 : camera.height, 0 : camera.width]  # (H, W) each
    rays = np.stack(  # (H, W, 3): camera-frame directions with z = 1
        [(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1], np.ones(depth.shape)], axis=-1
    )
    pose = camera_pose(camera)
    return (rays * depth[..., None]) @ pose[:3, :3].T + pose[:3, 3]  # (H, W, 3)
