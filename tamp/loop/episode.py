"""The closed loop: observe -> plan -> move -> check -> replan, in one simulator.

An episode lays out the problem's initial state, plans with the soft-T_P planner, and executes
the plan move by move. After each move it observes the block poses and reads the symbolic
state. A failed move, or a state that differs from the one the plan expected, triggers a
replan from the observed state (SS-Replan style: execute one action, observe, check); the
number of replans is bounded. Ground truth is read only at the end, to score the episode.

``observe="state"`` reads the symbolic state from block poses. ``observe="camera"`` reads it
from the simulator's camera image with the trained perception model (`tamp.camera.from_images`): the
goal is the perceived goal scene, a rendered completion of the problem's goal; each planning
window starts from the soft state perceived in the current image (frozen or
planning-optimised perception), only that window's moves are executed, and the next window
starts from a new image.
"""

from __future__ import annotations

import dataclasses
import enum
import time
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from motion.ik import IKSolver
from motion.trajectory import JointTrajectory, straight_segment
from perception import CHECKPOINT
from perception.errors import PerceptionError
from perception.perceive import Perceiver
from robots.panda import PANDA
from tamp.camera.from_images import ImageBeliefs, PerceptionMode, perceived_goal, perceived_state
from tamp.camera.render import StateRenderer
from tamp.loop.execute import ExecConfig, ExecutionResult, Failure, execute_move
from tamp.loop.faults import Injection, draw
from tamp.scene import PALETTE, Pose, Reading, SceneConfig, layout, read_state
from tamp.sim.base import Camera, Simulator
from tamp.sim.factory import make_simulator
from task.config import PlannerConfig
from task.domains import get_domain
from task.domains.blocksworld import complete_goal
from task.errors import TampError, one_of
from task.planner import plan
from task.problem import TABLE, Move, Problem

OBSERVE = ("state", "camera")
SETTLE_S = 0.3  # simulated seconds to let blocks come to rest before an observation


class EpisodeStatus(enum.Enum):
    GOAL_REACHED = "goal_reached"  # the observed state satisfies the goal
    NO_PLAN = "no_plan"  # the task planner found no plan from an observed state
    REPLAN_BUDGET = "replan_budget"  # more failures than ``max_replans``
    UNREADABLE = "unreadable"  # the observed poses do not form a blocksworld state
    OUT_OF_REACH = "out_of_reach"  # the same move had no IK solution twice in a row


@dataclass(frozen=True)
class LoopConfig:
    """Settings of an episode. ``grasp``: 'friction' (physical) or 'weld' (attach);
    ``observe``: 'state' (block poses) or 'camera' (perception of the camera image)."""

    sim: str = "pybullet"
    grasp: str = "friction"
    max_replans: int = 8
    max_tidies: int = 2  # attempts to put loose (leaning) blocks back on the table
    max_moves: int = 60
    planner: PlannerConfig = PlannerConfig()
    execution: ExecConfig = ExecConfig()
    scene: SceneConfig = SceneConfig()
    camera: Camera = Camera()
    inject: Injection = Injection()
    observe: str = "state"
    perception: PerceptionMode = PerceptionMode()  # camera only: frozen or optimised
    checkpoint: str | None = None  # camera only: perception weights (None: the shipped ones)

    def __post_init__(self) -> None:
        if self.observe not in OBSERVE:
            raise TampError(f"unknown observation {one_of(self.observe, OBSERVE)}")
        if self.observe == "camera" and self.perception.mode == "state":
            raise TampError("camera observation needs perception mode 'frozen' or 'optimised'")


@dataclass(frozen=True)
class EpisodeReport:
    """What happened in one episode; ``reached_goal`` is scored on simulator ground truth."""

    problem: str
    sim: str
    status: EpisodeStatus
    reached_goal: bool
    moves: tuple[ExecutionResult, ...]
    plans: tuple[tuple[str, ...], ...]  # every plan made, as move strings
    replans: int
    faults: tuple[str, ...]  # injected faults, e.g. "drop@3" (move index)
    disturbed: int  # moves after which a block other than the moved one changed support
    sim_time_s: float
    wall_time_s: float
    plan_time_s: float
    initial_plan_solved: bool = False  # the first task plan reached the goal symbolically
    reason: str = ""

    def to_json(self) -> dict:
        out = dataclasses.asdict(self)
        out["status"] = self.status.value
        out["moves"] = [
            {
                "move": str(r.move),
                "ok": r.ok,
                "failure": r.failure.value if r.failure else None,
                "evidence": r.evidence,
                "sim_time_s": round(r.sim_time_s, 3),
                "wall_time_s": round(r.wall_time_s, 3),
                "ik_time_s": round(r.ik_time_s, 4),
            }
            for r in self.moves
        ]
        return out


class Episode:
    """One problem in one simulator. ``run()`` returns the EpisodeReport."""

    def __init__(
        self,
        problem: Problem,
        config: LoopConfig = LoopConfig(),
        seed: int = 0,
        on_frame: Callable[[Simulator], None] | None = None,
        on_event: Callable[[str], None] | None = None,
        solver: IKSolver | None = None,
    ) -> None:
        self.problem, self.config, self.seed = problem, config, seed
        self.domain = get_domain(problem.domain)
        self.rng = np.random.default_rng(seed)
        self.on_frame = on_frame
        self.say = on_event or (lambda text: None)
        self.solver = solver or IKSolver()
        poses = layout(problem.entities, problem.init, config.scene, seed)
        self.status_text = ""
        self.target = problem  # what the robot plans for and tests: the goal it perceives
        self.perceived = None  # camera: the last perceived soft supports F (N, N + 1)
        self.image = None  # camera: the last camera image
        if config.observe == "camera":
            self._setup_camera()
        self.sim = make_simulator(
            config.sim, problem.entities, poses, config.scene, config.grasp, config.camera
        )

    def _setup_camera(self) -> None:
        """Load perception, render the goal scene and read the goal from it."""
        cfg, problem = self.config, self.problem
        self.perceiver = Perceiver.load(cfg.checkpoint or CHECKPOINT)
        goal_state = complete_goal(problem)
        with StateRenderer(cfg.sim, cfg.scene, cfg.camera) as renderer:
            self.goal_image = renderer.render(problem.entities, goal_state, self.seed + 1)
        self.target = perceived_goal(problem, self.perceiver, self.goal_image, cfg.perception.blur)

    # --- observation -----------------------------------------------------------------------
    def observe(self) -> dict[str, Pose]:
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

    def settle(self) -> None:
        hold = JointTrajectory.hold(self.sim.arm_q(), SETTLE_S, self.sim.dt)
        self.sim.run(hold, "open", on_frame=self.on_frame)

    def read(self) -> Reading:
        """The symbolic state the robot observes: from block poses, or from the camera."""
        if self.config.observe == "state":
            return read_state(self.problem.entities, self.observe(), self.config.scene)
        self.image = self.sim.render()
        try:
            state, F = perceived_state(
                self.target, self.perceiver, self.image, self.config.perception.blur
            )
        except PerceptionError as err:
            home = np.asarray(PANDA.q_home)
            if np.abs(self.sim.arm_q() - home).max() < 0.05:
                return Reading(None, (str(err),))
            # the arm may hide a block: take it home (high above the table) and look again
            self.status_text = "home to look again"
            self.sim.run(straight_segment(self.sim.arm_q(), home, self.sim.dt), "open",
                         on_frame=self.on_frame)  # fmt: skip
            return self.read()
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

    def _plan(self, state, seed: int):
        """Plan from ``state``; with the camera, one window from the current image."""
        current = dataclasses.replace(self.target, init=state)
        if self.config.observe == "state":
            return plan(current, self.config.planner, seed=seed)
        image = self.image
        beliefs = ImageBeliefs(
            [current], self.perceiver, lambda i, s: image, [self.goal_image],
            self.config.perception,
        )  # fmt: skip
        window = dataclasses.replace(self.config.planner, max_windows=1)
        return plan(current, window, seed=seed, beliefs=beliefs)

    def _true_state(self):
        return read_state(self.problem.entities, self.sim.block_poses(), self.config.scene).state

    # --- the loop --------------------------------------------------------------------------
    def run(self) -> EpisodeReport:
        """Run the episode to the goal or a stop; closes the simulator."""
        with _torch_threads(1):  # one small problem: thread hand-offs cost more than they give
            return self._run()

    def _run(self) -> EpisodeReport:
        cfg, problem = self.config, self.problem
        wall0 = time.perf_counter()
        moves: list[ExecutionResult] = []
        plans: list[tuple[str, ...]] = []
        faults: list[str] = []
        replans = disturbed = tidies = 0
        plan_time = 0.0
        target = self.target
        first_solved = self.domain.is_goal(target, problem.init)
        status, reason = EpisodeStatus.GOAL_REACHED, ""
        state = problem.init
        stalls = 0  # camera: windows in a row that decoded no move
        queue: list[Move] = []
        try:
            if cfg.observe == "camera":
                reading = self.read()
                state = reading.state
                if state is None:
                    status, reason = EpisodeStatus.UNREADABLE, "; ".join(reading.issues)
            while state is not None:
                if self.domain.is_goal(target, state):
                    break
                if not queue:
                    t0 = time.perf_counter()
                    result = self._plan(state, self.seed + len(plans))
                    plan_time += time.perf_counter() - t0
                    plans.append(tuple(str(m) for m in result.plan))
                    if len(plans) == 1:
                        first_solved = result.solved
                    window = cfg.observe == "camera" and len(result.plan) > 0
                    stalls = 0 if window or result.solved else stalls + 1
                    if not (result.solved or window):
                        if cfg.observe == "state" or stalls > cfg.max_replans:
                            status, reason = EpisodeStatus.NO_PLAN, "the planner found no plan"
                            break
                        continue
                    queue = list(result.plan)
                    self.say(f"plan {len(plans)}: {len(queue)} moves")
                if len(moves) >= cfg.max_moves:
                    status, reason = EpisodeStatus.REPLAN_BUDGET, f"{cfg.max_moves} moves used"
                    break
                move = queue.pop(0)
                expected = self.domain.apply_move(problem, state, move)
                drop = draw(self.rng, cfg.inject.drop) or len(moves) in cfg.inject.drop_moves
                drop_at = float(self.rng.uniform(0.2, 0.8)) if drop else None
                before = self._true_state()
                self.status_text = f"{move}"
                done = execute_move(
                    self.sim, self.solver, move, self.observe, cfg.execution, cfg.scene,
                    drop_at, self.on_frame,
                )  # fmt: skip
                if done.evidence.get("injected"):  # drawn, and the move reached its transit
                    faults.append(f"drop@{len(moves)}")
                nudge = draw(self.rng, cfg.inject.nudge) or len(moves) in cfg.inject.nudge_moves
                if done.ok and nudge:
                    self._nudge(move.entity)
                    faults.append(f"nudge@{len(moves)}")
                moves.append(done)
                self.settle()
                after = self._true_state()
                if before is not None and after is not None:
                    changed = [
                        x
                        for i, x in enumerate(problem.entities)
                        if x != move.entity and before[i] != after[i]
                    ]
                    disturbed += bool(changed)
                reading = self.read()
                self.say(f"{move}: " + ("ok" if done.ok else done.failure.value))
                if reading.state is None and tidies < cfg.max_tidies:
                    tidies += 1
                    reading = self._tidy(reading, moves)
                if reading.state is None:
                    status, reason = EpisodeStatus.UNREADABLE, "; ".join(reading.issues)
                    break
                state = reading.state
                if not done.ok or state != expected:
                    queue = []
                    replans += 1
                    why = describe(done) if not done.ok else "the state differs from the plan"
                    self.say(f"replan {replans}: {why}")
                    if _out_of_reach(moves):
                        status, reason = EpisodeStatus.OUT_OF_REACH, why
                        break
                    if replans > cfg.max_replans:
                        status = EpisodeStatus.REPLAN_BUDGET
                        reason = f"more than {cfg.max_replans} replans; last: {why}"
                        break
            truth = self._true_state()
            reached = truth is not None and self.domain.is_goal(problem, truth)
        finally:
            self.sim.close()
        return EpisodeReport(
            problem.name, cfg.sim, status, reached, tuple(moves), tuple(plans), replans,
            tuple(faults), disturbed, self.sim.time, time.perf_counter() - wall0, plan_time,
            first_solved, reason,
        )  # fmt: skip

    def _tidy(self, reading, moves: list[ExecutionResult]):
        """Recovery from an unreadable scene: put each loose block (leaning, on an edge) on a
        free table slot with an ordinary pick-and-place, then observe again."""
        for block in reading.loose:
            self.status_text = f"tidy {block}"
            done = execute_move(
                self.sim, self.solver, Move(block, TABLE), self.observe,
                self.config.execution, self.config.scene, None, self.on_frame,
            )  # fmt: skip
            moves.append(done)
            self.say(f"tidy {block} onto the table: " + describe(done))
            self.settle()
        return self.read()

    def _nudge(self, block: str) -> None:
        pose = self.sim.block_poses()[block]
        angle = self.rng.uniform(0, 2 * np.pi)
        d = self.config.inject.nudge_m
        x, y, z = pose.xyz
        # pushed off whatever it rests on: it falls to the table next to its support
        self.sim.set_block_pose(
            block, Pose((x + d * np.cos(angle), y + d * np.sin(angle), z), pose.yaw)
        )


@contextmanager
def _torch_threads(n: int):
    """Run the block with ``n`` torch intra-op threads, then restore the previous setting."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def describe(result: ExecutionResult) -> str:
    """One line on why a move failed, e.g. ``move(a -> table): ik_infeasible (pre_grasp ...)``."""
    if result.ok:
        return f"{result.move}: ok"
    ev = result.evidence
    if result.failure is Failure.IK_INFEASIBLE:
        xyz = ", ".join(f"{v:.3f}" for v in ev.get("target_xyz", ()))
        detail = f"no IK solution for the {ev.get('waypoint')} waypoint at ({xyz}) m"
    else:
        detail = ", ".join(f"{k} {v}" for k, v in ev.items() if not isinstance(v, dict))
    return f"{result.move}: {result.failure.value} ({detail})"


def _out_of_reach(moves: list[ExecutionResult]) -> bool:
    """The last two attempts were the same move and both found no IK solution."""
    last = moves[-2:]
    return (
        len(last) == 2
        and all(r.failure is Failure.IK_INFEASIBLE for r in last)
        and last[0].move == last[1].move
    )


def run_episode(problem: Problem, config: LoopConfig = LoopConfig(), seed: int = 0, **kw):
    """Run one episode of ``problem`` (see `Episode`) and return its EpisodeReport."""
    return Episode(problem, config, seed, **kw).run()
