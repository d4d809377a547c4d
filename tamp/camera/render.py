"""Camera images of Blocksworld states, rendered by either simulator.

``StateRenderer`` keeps one simulator with one block of every camera colour and teleports the
blocks of each state into place (unused blocks are parked out of view), so rendering a state
costs one camera image, not a simulator build. The same `tamp.scene.layout` that the motion
layer uses places the towers, so a rendered state looks like the scene the arm works in.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from tamp.scene import CAMERA_COLOURS, Pose, SceneConfig, SceneError, colour, layout
from tamp.sim.base import Camera, Lighting
from tamp.sim.factory import make_simulator

PARK = (5.0, 5.0)  # xy (m) where unused blocks wait, far outside every camera view


@dataclass(frozen=True)
class ViewJitter:
    """Random variation of a rendered view (the dataset's domain randomisation)."""

    eye_m: float = 0.03  # uniform +- on each camera eye coordinate
    target_m: float = 0.02  # uniform +- on each camera target coordinate
    fovy_deg: float = 1.5  # uniform +- on the field of view
    place_xy: float = 0.008  # block placement jitter, replaces SceneConfig.jitter_xy
    place_yaw: float = 0.3  # block yaw jitter, replaces SceneConfig.jitter_yaw


@dataclass(frozen=True)
class View:
    """How one image is taken (`StateRenderer.render`): the ``camera`` and the ``scene``'s
    settings (None: the renderer's own) and the ``lighting``."""

    camera: Camera | None = None
    lighting: Lighting = Lighting()
    scene: SceneConfig | None = None


PLAIN = View()  # the renderer's camera and scene, the default light


def random_lighting(rng: np.random.Generator) -> Lighting:
    """A light from a random direction above the table, random diffuse and ambient levels."""
    azimuth = rng.uniform(0.0, 2.0 * np.pi)
    tilt = rng.uniform(0.0, 0.9)  # rad from straight down
    direction = (
        float(np.sin(tilt) * np.cos(azimuth)),
        float(np.sin(tilt) * np.sin(azimuth)),
        -float(np.cos(tilt)),
    )
    return Lighting(direction, float(rng.uniform(0.5, 1.0)), float(rng.uniform(0.25, 0.6)))


def jitter_camera(camera: Camera, jitter: ViewJitter, rng: np.random.Generator) -> Camera:
    """``camera`` with its eye, target and field of view moved within ``jitter``."""
    eye = np.asarray(camera.eye) + rng.uniform(-jitter.eye_m, jitter.eye_m, 3)
    target = np.asarray(camera.target) + rng.uniform(-jitter.target_m, jitter.target_m, 3)
    fovy = camera.fovy + rng.uniform(-jitter.fovy_deg, jitter.fovy_deg)
    return replace(
        camera,
        eye=tuple(float(v) for v in eye),
        target=tuple(float(v) for v in target),
        fovy=float(fovy),
    )


class StateRenderer:
    """Images of block states from one reusable simulator (``'pybullet'`` or ``'mujoco'``).

    Block ``i`` of a problem gets the scene's palette colour ``i`` unless ``colours`` says
    otherwise; at most `CAMERA_COLOURS` blocks, since perception tells blocks apart by colour.
    """

    def __init__(
        self, sim: str = "pybullet", scene: SceneConfig = SceneConfig(), camera: Camera = Camera()
    ) -> None:
        self.names = tuple(name for name, _ in scene.palette[:CAMERA_COLOURS])
        self.scene = scene
        self.camera = camera
        self.sim = make_simulator(sim, self.names, self._parked(), scene, camera=camera)

    def _parked(self) -> dict[str, Pose]:
        half = self.scene.block_size / 2
        return {n: Pose((PARK[0] + 0.2 * i, PARK[1], half)) for i, n in enumerate(self.names)}

    def render(
        self,
        entities: Sequence[str],
        state: Sequence[str],
        seed: int = 0,
        colours: Sequence[int] | None = None,
        view: View = PLAIN,
        slots: Sequence[int] | None = None,
    ) -> np.ndarray:
        """RGB image (H, W, 3) uint8 of ``state`` (supports in ``entities`` order).

        ``seed`` picks the tower slots (unless ``slots`` gives them) and jitter
        (`tamp.scene.layout`); ``colours`` gives the palette index of each entity (default 0, 1,
        2, ...); ``view``: the camera, light and scene settings of this image.
        """
        self.place(entities, state, seed, colours, view, slots)
        return self.sim.render()

    def place(
        self,
        entities: Sequence[str],
        state: Sequence[str],
        seed: int = 0,
        colours: Sequence[int] | None = None,
        view: View = PLAIN,
        slots: Sequence[int] | None = None,
    ) -> dict[str, Pose]:
        """Set up the view of `render` without rendering; returns each entity's true pose (the
        caller renders with ``self.sim``, e.g. `Simulator.render_rgbd`)."""
        colours = list(range(len(entities))) if colours is None else list(colours)
        k = len(self.names)
        if len(entities) > k:
            raise SceneError(f"{len(entities)} blocks, but the camera tells at most {k} apart")
        if len(colours) != len(entities) or len(set(colours)) != len(colours):
            raise SceneError(f"colours must give each of the {len(entities)} blocks its own index")
        if any(not 0 <= c < k for c in colours):
            raise SceneError(f"colour indices must lie in 0..{k - 1}, got {colours}")
        poses = layout(entities, state, view.scene or self.scene, seed, slots)
        placed = self._parked()
        for x, c in zip(entities, colours, strict=True):
            placed[self.names[c]] = poses[x]
        for name, pose in placed.items():
            self.sim.set_block_pose(name, pose)
        self.sim.set_view(view.camera or self.camera, view.lighting)
        return poses

    def close(self) -> None:
        self.sim.close()

    def __enter__(self) -> StateRenderer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def block_colours(n: int) -> list[tuple[float, float, float]]:
    """RGB in [0, 1] of the first ``n`` palette colours (what perception looks for)."""
    return [colour(i) for i in range(n)]
