"""`LoopConfig`: the settings of one closed-loop episode (simulator, grasp, budgets, faults,
what the robot observes)."""

from __future__ import annotations

from dataclasses import dataclass

from tamp.camera.from_images import PerceptionMode
from tamp.loop.execute import CollisionMode, ExecConfig
from tamp.loop.faults import Injection
from tamp.modes import Crisp, Observation, Perception
from tamp.scene import SceneConfig
from tamp.sim.base import Camera
from task.config import PlannerConfig
from task.domains.blocksworld import NAME as BLOCKSWORLD
from task.errors import TampError, member


@dataclass(frozen=True)
class LoopConfig:
    """Settings of an episode. ``grasp``: 'friction' (physical) or 'weld' (attach);
    ``observe``: 'state' (block poses) or 'camera' (perception of the camera image);
    ``crisp``: what decoded moves are checked against, 'perceived' (the observed state, what a
    robot has) or 'true' (simulator ground truth, an oracle variant). The loop sets its own
    planning basis, so ``perception.crisp`` is not used here."""

    sim: str = "pybullet"
    grasp: str = "friction"
    max_replans: int = 8
    max_tidies: int = 2  # attempts to put loose (leaning) blocks back on the table
    max_moves: int = 60
    # the loop executes Blocksworld problems: Blocksworld's planner defaults, as ``tamp plan``
    # plans them (`PlannerConfig.for_domain`): from 16 blocks its constructive moves without a
    # window and windows over the part a window reaches, not all the blocks (300: 40 s a window)
    planner: PlannerConfig = PlannerConfig.for_domain(BLOCKSWORLD)
    execution: ExecConfig = ExecConfig()
    scene: SceneConfig = SceneConfig()
    camera: Camera = Camera()
    inject: Injection = Injection()
    observe: Observation = Observation.STATE
    perception: PerceptionMode = PerceptionMode()  # camera only: frozen or optimised
    checkpoint: str | None = None  # camera only: perception weights (None: the shipped ones)
    crisp: Crisp = Crisp.PERCEIVED  # decode against the observed state; "true": against the truth
    placements: float = 0.0  # m: motion-aware, state: a block may go this far from a place's
    # centre, where the planner's Adam puts it (continuous placements; 0: the centre)
    # motion-aware, state, fixed places: the planner's windows check each move they keep with
    # the executor's own check on the poses they predict, before anything runs, and rule out
    # where it starts a move that fails it (`tamp.arm.costs.ArmCosts.verify`). Off: on issue
    # 13's cramped and shelf episodes it changed no outcome and cost planning time (BENCHMARKS)
    check_ahead: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "observe", member(Observation, self.observe, "observation"))
        object.__setattr__(self, "crisp", member(Crisp, self.crisp, "crisp protocol"))
        if not 0.0 <= self.placements <= 0.03:
            raise TampError(
                f"placements must lie in [0, 0.03] m (a block stays on its slot), "
                f"got {self.placements}"
            )
        if self.check_ahead and (
            self.observe is not Observation.STATE
            or self.placements > 0
            or self.planner.lambda_motion <= 0
            or self.execution.collision is CollisionMode.OFF
        ):
            raise TampError(
                "check_ahead needs motion-aware planning (lambda_motion > 0) with state "
                "observation, fixed places (placements 0) and the collision model on"
            )
        if self.observe is Observation.CAMERA and self.perception.mode is Perception.STATE:
            raise TampError("camera observation needs perception mode 'frozen' or 'optimised'")
