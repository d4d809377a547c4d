"""The two block-pose sensors the loop can have, one per ``LoopConfig.observe`` setting.

- `MocapPoses` (``observe="state"``): a motion-capture oracle. Its documented sensor is the
  true block poses, so it reads ``sim.truth`` inside ``GroundTruth.oracle()``; it is built only
  in state mode, and the camera mode has no way to reach it.
- `CameraPoses` (``observe="camera"``): block poses estimated from one RGB-D image of the
  simulator's camera (`tamp.camera.poses.estimate_poses`); raises `PerceptionError` naming a
  block it cannot see.

Injected observation noise and looking again from home are the observer's business
(`tamp.loop.observe.Observer`), not the sensors'.
"""

from __future__ import annotations

import numpy as np

from tamp.camera.poses import estimate_poses
from tamp.camera.render import block_colours
from tamp.scene import Pose, SceneConfig
from tamp.sim.base import Simulator


class MocapPoses:
    """The oracle pose sensor of ``observe="state"``: every block's true pose (centre, yaw)."""

    def __init__(self, sim: Simulator) -> None:
        self.truth = sim.truth

    def __call__(self) -> dict[str, Pose]:
        with self.truth.oracle():
            return self.truth.block_poses()


class CameraPoses:
    """Block poses from the depth camera: one RGB-D image per call, nothing from the simulator
    but its pixels."""

    def __init__(self, sim: Simulator, entities: tuple[str, ...], scene: SceneConfig) -> None:
        self.sim, self.entities, self.scene = sim, entities, scene
        self.colours = block_colours(len(entities))
        self._frame: tuple[float, np.ndarray, np.ndarray] | None = None

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """The RGB-D image (H, W, 3) uint8, (H, W) float32 metres of the scene now. Rendered once
        per simulated instant: the state read after a move and the next move's pick poses look
        at the same scene (every change to it, teleports included, is followed by simulated
        time before the next look)."""
        if self._frame is None or self._frame[0] != self.sim.time:
            self._frame = (self.sim.time, *self.sim.render_rgbd())
        return self._frame[1], self._frame[2]

    def __call__(self) -> dict[str, Pose]:
        rgb, depth = self.frame()
        return estimate_poses(
            rgb, depth, self.sim.camera, self.entities, self.colours, self.scene.block_size
        )
