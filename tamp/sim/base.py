"""The one simulator interface both backends implement, and the shared control loop.

A backend owns a world with the Panda, a table and the blocks of a scene. The same
`motion.trajectory.JointTrajectory` (sampled at the simulator's ``dt`` = 2 ms in both
backends) drives both. The physics steps ``physics_dt`` = 4 ms (`PHYSICS_DT`): each step gets
the joint targets of the last trajectory sample it covers, so every other sample is commanded
(the controller runs at 250 Hz; a 2 ms step cost twice the wall time, and the grasps, tracking
and scores hold at 4 ms). What the loop
may sense is what a real robot has: joint positions, finger opening and the contact force on
each finger (from whatever it touches), and camera images. The true block poses, and the
snapshots a video is drawn from, sit behind ``sim.truth`` (`tamp.sim.truth.GroundTruth`), which
scores episodes and which an episode locks.

Contact scoring (``Simulator.touched``, the experimenter's, never a sensor): after every physics
step, whatever touches the arm, the hand or the block held in it is counted (in physics steps
of ``physics_dt``), except the contacts the running trajectory is meant to make (`Expected`).
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from motion.trajectory import JointTrajectory
from tamp.outcome import Failure
from tamp.scene import Body, Pose, SceneConfig, cube_yaw
from tamp.sim.truth import GroundTruth, Snapshot
from task.errors import TampError, one_of

SIMULATORS = ("pybullet", "mujoco")
DT = 0.002  # s, the period trajectories are sampled at (`Simulator.dt`)
PHYSICS_DT = 0.004  # s, the physics step of both backends: two trajectory samples
TRACK_EVERY = 5  # trajectory samples between tracking-error measurements
ROBOT = "robot"  # `Simulator._contacts`' name for any link of the Panda
HELD = "held:"  # `Simulator.touched` key prefix of what the held block touched, e.g. "held:c"
VIDEO_SIZE = (640, 480)  # (width, height) of `Simulator.render_video` frames
# the heaviest movable object, kg: 0.3 kg hangs on the friction grasp of either backend with
# margin at any width in the stroke (the weakest: MuJoCo's tendon grip on a 2 cm object)
MAX_MASS = 0.3
MIN_MASS = 0.01  # kg, the lightest (a 2 cm cube would weigh 6 g at the default density)


def body_mass(scene: SceneConfig, name: str) -> float:
    """Mass (kg) of entity ``name``: the default block's density (``block_mass`` over the
    default body's volume; 800 kg/m^3 for 0.1 kg 5 cm cubes) times its body's volume, within
    [`MIN_MASS`, `MAX_MASS`]; the default block weighs exactly ``block_mass``."""
    body = scene.body(name)
    if body == scene.default_body:
        return scene.block_mass
    density = scene.block_mass / scene.default_body.volume
    return min(max(density * body.volume, MIN_MASS), MAX_MASS)


def body_yaw(rotation, body: Body) -> float:
    """Yaw (rad) of a body from its rotation matrix (3, 3), modulo its symmetry about the
    vertical: an upright cuboid's x axis in [-pi/2, pi/2); a cube's, as `tamp.scene.cube_yaw`
    reads it, in [-pi/4, pi/4), and so a cylinder's (it has no yaw of its own), a cuboid's
    with a square footprint or one that is not upright."""
    r = np.asarray(rotation, dtype=float).reshape(3, 3)  # columns: body axes in the world
    square = body.half[0] == body.half[1]
    if body.kind != "cuboid" or square or int(np.argmax(np.abs(r[2]))) != 2:
        return cube_yaw(r)
    return (math.atan2(r[1, 0], r[0, 0]) + math.pi / 2) % math.pi - math.pi / 2


@dataclass(frozen=True)
class Camera:
    """A pinhole camera looking at ``target`` from ``eye``; ``fovy`` in degrees.

    The default looks at the slot grid from the front right, 40 degrees above the table, along
    an azimuth (x : y = 2 : 1) that lines up with no diagonal of the grid, so a tower rarely
    hides a block behind it.
    """

    eye: tuple[float, float, float] = (1.22, -0.38, 0.81)
    target: tuple[float, float, float] = (0.47, 0.0, 0.1)
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fovy: float = 40.0
    width: int = 320
    height: int = 240


@dataclass(frozen=True)
class Lighting:
    """One directional light: ``direction`` it shines along (world frame), diffuse and ambient
    intensities in [0, 1]. Both backends map these onto their own lighting models."""

    direction: tuple[float, float, float] = (-0.2, -0.1, -1.0)
    diffuse: float = 0.8
    ambient: float = 0.4


@dataclass(frozen=True)
class GripperReading:
    """What the finger sensors give: the opening between the fingers (m) and the total normal
    contact force (N) on each finger from anything it touches except the robot itself. A
    fingertip sensor cannot tell what it touches, so neither can this."""

    width: float
    left_force: float
    right_force: float


@dataclass(frozen=True)
class Expected:
    """The contacts a trajectory is meant to make, which contact scoring does not count
    (`Simulator.run`): the arm on ``handled``, the block the current move picks and places;
    and, while ``held`` is in the hand, that block on ``rests`` (what it leaves or is put onto
    in this phase: block names or "table"). Every other contact of the arm or the held block
    counts in `Simulator.touched`; the default expects none."""

    handled: str | None = None
    held: str | None = None
    rests: frozenset[str] = frozenset()


class Simulator(abc.ABC):
    """A headless world: the Panda (at home, fingers open), a table, and blocks at ``poses``
    (each entity's solid is ``scene.body(name)``: by default cubes or cylinders, as
    ``scene.shape`` says; its mass `body_mass`; block i has ``scene.palette[i]``'s colour)."""

    name: str = ""
    dt: float = DT
    physics_dt: float = PHYSICS_DT

    def __init__(
        self,
        entities: Sequence[str],
        poses: Mapping[str, Pose],
        scene: SceneConfig = SceneConfig(),
        grasp: str = "friction",
        camera: Camera = Camera(),
        video: bool = False,
    ) -> None:
        if grasp not in ("friction", "weld"):
            raise TampError(f"unknown grasp mode {one_of(grasp, ('friction', 'weld'))}")
        self.entities = tuple(entities)
        self.scene = scene
        self.grasp = grasp
        self.camera = camera
        self.video = video  # a world for `show` and `render_video` only (see `render_video`)
        self.lighting = Lighting()
        self.time = 0.0
        self.frame_period = 0.2  # simulated seconds between ``on_frame`` calls
        self._next_frame = 0.0  # simulated time of the next ``on_frame`` call, across runs
        # scoring and videos only; see tamp.sim.truth
        self.truth = GroundTruth(self._block_poses, self._snapshot)
        # scoring only: what the arm, the hand or the held block touched while running
        # trajectories and was not expected to (name, or "held:" + name -> physics steps)
        self.touched: dict[str, int] = {}
        # the block the running trajectory holds (`Expected.held`, None between runs): scoring
        # counts the contacts of the arm and of this block only, and `_contacts` may omit others
        self._held: str | None = None

    # --- what a backend implements -------------------------------------------------------
    @abc.abstractmethod
    def _command(self, q: np.ndarray, qd: np.ndarray, gripper: str) -> None:
        """Set the arm joint targets (J,) and the gripper command for the next step."""

    @abc.abstractmethod
    def _step(self) -> None:
        """Advance the physics by ``dt``."""

    @abc.abstractmethod
    def arm_q(self) -> np.ndarray:
        """Measured arm joint positions (J,)."""

    @abc.abstractmethod
    def gripper(self) -> GripperReading:
        """Finger opening and the normal contact force on each finger from anything but the
        robot (the finger sensors)."""

    @abc.abstractmethod
    def _contacts(self) -> set[tuple[str, str]]:
        """The pairs of things in contact now, by name: blocks, obstacles, "table", and
        `ROBOT` for any link of the Panda (scoring only, see `Simulator.run`). Every pair with
        the arm or with the block held now (``self._held``) is there; a backend may leave out
        the others, which scoring never counts."""

    @abc.abstractmethod
    def _block_poses(self) -> dict[str, Pose]:
        """Ground-truth block poses (centre, yaw); read them through ``self.truth`` only."""

    @abc.abstractmethod
    def set_block_pose(self, block: str, pose: Pose) -> None:
        """Teleport a block (fault injection); its velocity is zeroed."""

    @abc.abstractmethod
    def attach(self) -> bool:
        """The ``weld`` grasp mode: weld to the hand, where it is now, the block the closed
        fingers hold, i.e. the one body that both fingers touch (what the finger contacts give a
        real gripper). False, and nothing welded, when the fingers hold no block. The caller
        learns no name: the robot cannot tell which block it holds."""

    @abc.abstractmethod
    def detach(self) -> None:
        """Remove any weld."""

    @abc.abstractmethod
    def render(self) -> np.ndarray:
        """An RGB image (H, W, 3) uint8 from ``camera``."""

    @abc.abstractmethod
    def render_rgbd(self) -> tuple[np.ndarray, np.ndarray]:
        """An RGB image (H, W, 3) uint8, as `render` gives it, and its depth (H, W) float32.

        Depth is z-depth in metres: the distance from the camera's eye along its optical axis
        (eye -> target), not the length of the ray through the pixel. Pixels that see nothing
        read the backend's far plane. `tamp.camera.geometry.backproject` turns it into points.
        """

    @abc.abstractmethod
    def render_video(self, size: tuple[int, int] = VIDEO_SIZE) -> np.ndarray:
        """An RGB image (H, W, 3) uint8 of ``size`` (W, H) from ``camera``'s viewpoint, for
        people to watch. It never changes what `render` gives perception: a backend may draw it
        with another renderer (PyBullet: OpenGL through its EGL plugin in a world made with
        ``video=True``, which then draws nothing else; TinyRenderer otherwise)."""

    @abc.abstractmethod
    def _snapshot(self) -> Snapshot:
        """The arm, fingers and blocks as they are now: the true block poses, so read it through
        ``self.truth.snapshot()`` only (for videos, not a sensor)."""

    @abc.abstractmethod
    def show(self, snapshot: Snapshot) -> None:
        """Put the arm, fingers and blocks where ``snapshot`` says (kinematics only, no physics
        step): a second world renders another's frames this way."""

    @abc.abstractmethod
    def set_view(self, camera: Camera, lighting: Lighting) -> None:
        """Move the camera and change the light for the next ``render``."""

    @abc.abstractmethod
    def set_colour(self, part: str, rgb: Sequence[float]) -> None:
        """Recolour a block (by name), the ``'floor'`` or the ``'backdrop'`` (RGB in [0, 1])
        for the next ``render``; a scene without a backdrop ignores ``'backdrop'``."""

    def _check_part(self, part: str) -> None:
        parts = (*self.entities, "floor", "backdrop")
        if part not in parts:
            raise TampError(f"unknown part to colour {one_of(part, parts)}")

    @abc.abstractmethod
    def close(self) -> None:
        """Free the simulator."""

    # --- shared control ------------------------------------------------------------------
    def run(
        self,
        trajectory: JointTrajectory,
        gripper: str,
        release_at: float | None = None,
        on_frame: Callable[[Simulator], None] | None = None,
        expected: Expected = Expected(),
    ) -> float:
        """Track ``trajectory`` (sampled every ``dt``) with the gripper held at ``gripper``.

        Each physics step of ``physics_dt`` covers `stride` samples and commands the last of
        them (the final step the trajectory's last sample). ``release_at`` (s into the
        trajectory) opens the gripper at the first commanded sample at or after it (fault
        injection: a drop; from then on nothing is held). ``on_frame(self)`` is called every
        ``self.frame_period`` simulated seconds, on one clock across runs (a video's frames stay
        evenly spaced over many moves). After every physics step, the contacts of the arm and
        of the held block that ``expected`` does not name are counted in ``touched``. Returns
        the largest joint tracking error (rad) against the commanded sample, measured after
        the first step, then once the commanded samples pass each further ``TRACK_EVERY``
        samples, and after the last step.
        """
        worst = 0.0
        last = len(trajectory.times) - 1
        self._held = expected.held
        tracked = -1  # the last TRACK_EVERY bucket whose tracking error was measured
        for k in self.commanded(last + 1):
            if release_at is not None and trajectory.times[k] >= release_at:
                gripper = "open"
                self.detach()
                expected = replace(expected, held=None, rests=frozenset())
                self._held = None
            self._command(trajectory.positions[k], trajectory.velocities[k], gripper)
            self._step()
            self.time += self.physics_dt
            self._count_contacts(expected)
            if k // TRACK_EVERY != tracked or k == last:
                tracked = k // TRACK_EVERY
                worst = max(worst, float(np.abs(self.arm_q() - trajectory.positions[k]).max()))
            if on_frame is not None and self.time >= self._next_frame:
                on_frame(self)
                self._next_frame = max(self._next_frame + self.frame_period, self.time)
        self._held = None
        return worst

    @property
    def stride(self) -> int:
        """Trajectory samples per physics step (``physics_dt / dt``, a whole number)."""
        return max(1, round(self.physics_dt / self.dt))

    def commanded(self, samples: int) -> list[int]:
        """Indices of the samples that `run` commands, one per physics step, of a trajectory
        with ``samples`` samples: the last sample each step covers (``stride - 1``,
        ``2 stride - 1``, ...), and the trajectory's last sample for the final step."""
        s = self.stride
        return [min(k, samples - 1) for k in range(s - 1, samples + s - 1, s)]

    def _count_contacts(self, expected: Expected) -> None:
        """Count in ``touched`` this step's unexpected contacts of the arm and the held block."""
        hit = set()
        for pair in self._contacts():
            for me, other in (pair, pair[::-1]):
                if me == ROBOT and other not in (ROBOT, expected.handled):
                    hit.add(other)
                elif me == expected.held and other != ROBOT and other not in expected.rests:
                    hit.add(HELD + other)
        for name in hit:
            self.touched[name] = self.touched.get(name, 0) + 1

    def __enter__(self) -> Simulator:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def holding(sim: Simulator, width: float, config, fresh: bool) -> dict | None:
    """None when the fingers hold an object ``width`` (m) wide: opened to that width within
    ``config.width_tol`` and, on a fresh grasp, both pushing at least ``config.min_force``
    (a weld grasp holds once made); otherwise the evidence that they do not. ``config``: anything
    with those two fields (`tamp.loop.execute.ExecConfig`, `tamp.geo.execute.RunConfig`). What
    the finger sensors say, so both executors read a grasp the same way."""
    r = sim.gripper()
    wide = abs(r.width - width) <= config.width_tol
    floor = config.min_force if fresh else 0.0
    both = r.left_force > floor and r.right_force > floor
    if wide and (both or (sim.grasp == "weld" and not fresh)):
        return None
    return {
        "finger_width": round(r.width, 4),
        "grasp_width": round(width, 4),
        "left_force": round(r.left_force, 3),
        "right_force": round(r.right_force, 3),
    }


def lost_hold(
    sim: Simulator,
    phase: str,
    width: float,
    config,
    on_frame: Callable[[Simulator], None] | None,
    handling: Expected,
    weld_missed: Callable[[Simulator], dict],
) -> tuple[Failure, dict] | None:
    """What went wrong with the held object after phase ``phase``, with its evidence (both
    executors': `tamp.loop.execute`, `tamp.geo.execute`): GRASP_MISSED when the closed gripper
    (``width`` apart, `holding`) holds nothing, or, on a welded grasp, when no object lies
    between the fingers (evidence ``weld_missed(sim)``); DROPPED when it left the hand in the
    lift or the transit (the hand then opens and holds still for 0.5 s, ``handling`` the
    contacts expected meanwhile); else None."""
    from motion.trajectory import JointTrajectory  # ruckig: loaded only where a hand moves

    if phase == "close":
        missed = holding(sim, width, config, fresh=True)
        if missed is None and sim.grasp == "weld" and not sim.attach():
            missed = weld_missed(sim)
        return None if missed is None else (Failure.GRASP_MISSED, missed)
    if phase in ("lift", "transit"):
        gone = holding(sim, width, config, fresh=False)
        if gone is not None:
            sim.detach()
            hold = JointTrajectory.hold(sim.arm_q(), 0.5, sim.dt)
            sim.run(hold, "open", on_frame=on_frame, expected=handling)
            return Failure.DROPPED, gone
    return None
