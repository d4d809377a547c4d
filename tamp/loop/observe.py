"""What the robot senses: block poses with injected noise, or the camera image read by the
trained perception model, turned into the symbolic state it plans from.

``observe="state"`` reads the state from block poses (`tamp.scene.read_state`).
``observe="camera"`` reads it from the simulator's camera image (`tamp.camera.from_images`);
when perception fails while the arm is away from home, the arm may hide a block, so it goes
home (high above the table) and looks again. The goal, too, is perceived: from a rendered
completion of the problem's goal (`camera_goal`).
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
from tamp.loop.config import LoopConfig
from tamp.loop.faults import draw
from tamp.scene import PALETTE, Pose, Reading, read_state
from tamp.sim.base import Simulator
from task.domains.blocksworld_states import complete_goal
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
    perceiver = Perceiver.load(config.checkpoint or CHECKPOINT)
    goal_state = complete_goal(problem)
    with StateRenderer(config.sim, config.scene, config.camera) as renderer:
        goal_image = renderer.render(problem.entities, goal_state, seed + 1)
    target = perceived_goal(problem, perceiver, goal_image, config.perception.blur)
    return perceiver, goal_image, target


class Observer:
    """The robot's senses in ``sim``. Noise draws come from the episode's ``rng``; with the
    camera, ``image`` and ``perceived`` keep the last image and its soft supports."""

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
        self.perceived = None  # camera: the last perceived soft supports F (N, N + 1)

    def poses(self) -> dict[str, Pose]:
        """Block poses as the robot sees them: true poses, plus injected noise."""
        poses = self.sim.block_poses()
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
        self.image = self.sim.render()
        try:
            state, F = perceived_state(
                self.target, self.perceiver, self.image, self.config.perception.blur
            )
        except PerceptionError as err:
            home = np.asarray(PANDA.q_home)
            if np.abs(self.sim.arm_q() - home).max() < HOME_TOL:
                return Reading(None, (str(err),))
            # the arm may hide a block: take it home (high above the table) and look again
            show("home to look again")
            self.sim.run(straight_segment(self.sim.arm_q(), home, self.sim.dt), "open",
                         on_frame=on_frame)  # fmt: skip
            return self.read(on_frame, show)
        self.perceived = F
        return Reading(state)

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
