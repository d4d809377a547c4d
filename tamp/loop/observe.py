"""What the robot senses: block poses (for picking and placing) and the symbolic state it plans
from, each from the sensor its observation mode has (`tamp.loop.sensors`).

``observe="state"``: poses from the motion-capture oracle (`MocapPoses`, the one sensor that
reads simulator ground truth, by design), optionally with injected noise; the state is read
from them (`tamp.world.convert.from_poses.read_state`).
``observe="camera"``: poses estimated from one RGB-D image per observation (`CameraPoses`);
the state is read from the camera image by the trained perception model
(`tamp.camera.from_images`). When the camera cannot see a block while the arm is away from
home, the arm may hide it, so the arm goes home (high above the table) and looks again; a block
still unseen from home raises `PerceptionError` for ``poses`` and gives an unreadable state for
``read``. The goal, too, is perceived: from a rendered completion of the problem's goal
(`camera_goal`). Nothing here reads ground truth in camera mode.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from motion.trajectory import JointTrajectory, straight_segment
from perception import CHECKPOINT
from perception.errors import PerceptionError
from perception.perceive import Perceiver
from robots.panda import PANDA
from tamp.camera.from_images import perceived_goal, perceived_state
from tamp.camera.render import StateRenderer
from tamp.camera.states import complete_goal
from tamp.loop.config import LoopConfig
from tamp.loop.faults import draw
from tamp.loop.sensors import CameraPoses, MocapPoses
from tamp.scene import PALETTE, Pose
from tamp.sim.base import Simulator
from tamp.world.convert.from_poses import Reading, read_state
from task.problem import TABLE, Problem

SETTLE_S = 0.3  # simulated seconds to let blocks come to rest before an observation
HOME_TOL = 0.05  # rad: the arm counts as home within this of every home joint angle

OnFrame = Callable[[Simulator], None] | None


def _silent(text: str) -> None:
    """Show nothing."""


def camera_goal(problem: Problem, config: LoopConfig, seed: int):
    """Load perception, render the goal scene and read the goal from it.

    Returns ``(perceiver, goal_image, target)``: ``target`` is ``problem`` with the perceived
    goal, what the robot plans for and tests.
    """
    # workcell renders, read on the planner's device
    perceiver = Perceiver.load(config.checkpoint or CHECKPOINT, "cubes", config.planner.device)
    goal_state = complete_goal(problem)
    with StateRenderer(config.sim, config.scene, config.camera) as renderer:
        goal_image = renderer.render(problem.entities, goal_state, seed + 1)
    target = perceived_goal(problem, perceiver, goal_image, config.perception.blur)
    return perceiver, goal_image, target


class Observer:
    """The robot's senses in ``sim``: the pose sensor of ``config.observe`` (the mocap oracle is
    built only for ``"state"``), and for ``"camera"`` the perception model. Noise draws come
    from the episode's ``rng``; ``image`` and ``perceived`` keep the last camera image and its
    soft supports."""

    def __init__(
        self,
        sim: Simulator,
        problem: Problem,
        config: LoopConfig,
        rng: np.random.Generator,
        target: Problem,
        perceiver: Perceiver | None = None,
    ) -> None:
        self.sim, self.problem, self.config, self.rng = sim, problem, config, rng
        self.target, self.perceiver = target, perceiver
        self.image = None  # camera: the last camera image
        # checks (and reroutes) the trip home against the known obstacles: None when no safe
        # way is found; unset, the arm goes home on a straight joint segment
        self.home_guard: Callable[[JointTrajectory], JointTrajectory | None] | None = None
        self.perceived = None  # camera: the last perceived soft supports F (N, N + 1)
        if config.observe == "state":
            self.sensor = MocapPoses(sim)
        else:
            self.sensor = CameraPoses(sim, problem.entities, config.scene)

    def poses(
        self, on_frame: OnFrame = None, show: Callable[[str], None] = _silent
    ) -> dict[str, Pose]:
        """Every block's pose as the robot sees it (plus injected noise): from the mocap oracle,
        or from the depth camera, going home to look again when a block is hidden. Raises
        `PerceptionError` when the camera cannot see a block even from home."""
        if self.config.observe == "state":
            poses = self.sensor()
        else:
            poses = self._look(self.sensor, on_frame, show)
        inj = self.config.inject
        if draw(self.rng, inj.noise):
            noise = self.rng.normal(0.0, inj.noise_sigma, size=(len(poses), 3))
            poses = {
                k: Pose(tuple(float(v) for v in np.add(p.xyz, n)), p.yaw)
                for (k, p), n in zip(poses.items(), noise, strict=True)
            }
        return poses

    def settle(self, on_frame: OnFrame = None) -> None:
        """Hold the arm still for ``SETTLE_S`` so the blocks come to rest."""
        hold = JointTrajectory.hold(self.sim.arm_q(), SETTLE_S, self.sim.dt)
        self.sim.run(hold, "open", on_frame=on_frame)

    def read(self, on_frame: OnFrame = None, show: Callable[[str], None] = _silent) -> Reading:
        """The symbolic state the robot observes: from block poses, or from the camera.
        ``show`` announces a trip home to look again; ``on_frame`` sees that move."""
        if self.config.observe == "state":
            return read_state(self.problem.entities, self.poses(), self.config.scene)
        try:
            state, self.perceived = self._look(self._perceive, on_frame, show)
        except PerceptionError as err:
            return Reading(None, (str(err),))
        return Reading(state)

    def _perceive(self):
        """One camera image, read by the perception model: (state, soft supports F)."""
        self.image = self.sensor.frame()[0]  # the RGB of the camera's RGB-D image
        return perceived_state(self.target, self.perceiver, self.image, self.config.perception.blur)

    def _look(self, look: Callable, on_frame: OnFrame, show: Callable[[str], None]):
        """``look()`` with the camera; when it cannot see a block while the arm is away from
        home, the arm may hide it: take the arm home (high above the table) and look again.
        From home, the `PerceptionError` stands."""
        home = np.asarray(PANDA.q_home)
        try:
            return look()
        except PerceptionError:
            if np.abs(self.sim.arm_q() - home).max() < HOME_TOL:
                raise
            way = straight_segment(self.sim.arm_q(), home, self.sim.dt)
            if self.home_guard is not None:
                way = self.home_guard(way)
                if way is None:  # no collision-free way home: the block stays unseen
                    raise
        show("home to look again")
        self.sim.run(way, "open", on_frame=on_frame)
        return look()

    def belief_lines(self) -> list[str]:
        """The last perceived soft state, one line per block: its most likely support and that
        support's probability, by colour (empty when observing block poses)."""
        if self.perceived is None:
            return []
        F = self.perceived  # (N, N + 1): blocks, then the table
        names = [PALETTE[i][0] for i in range(self.target.n)] + [TABLE]
        lines = []
        for x, row in enumerate(F):
            p, col = row.max(0)
            lines.append(f"{names[x]} on {names[int(col)]} {float(p):.2f}")
        return lines
