"""The closed loop: observe -> plan -> move -> check -> replan, in one simulator.

An episode lays out the problem's initial state, plans with the soft-T_P planner, and executes
the plan move by move. After each move it observes (`tamp.loop.observe`) and reads the symbolic
state. A failed move, or a state that differs from the one the plan expected, triggers a
replan from the observed state (SS-Replan style: execute one action, observe, check); the
number of replans is bounded. The episode locks the simulator's ground truth (``sim.truth``)
for its whole run: only its `Scorer` (disturbed stacks, the final goal check), the injected
nudge (the experimenter) and, with ``observe="state"``, the mocap oracle may read it; any other
read raises `tamp.sim.truth.GroundTruthLeak`.

With ``observe="camera"`` the goal is the perceived goal scene; each planning window starts
from the soft state perceived in the current image (frozen or planning-optimised perception),
only that window's moves are executed, and the next window starts from a new image.

The loop is a few public steps, which `run` (through `play`) and
`tamp.loop.given.GivenPlanEpisode` both drive: `start` a tally, `step` (plan when nothing is
queued, then the next move), `execute` one move with its faults and its score, `check` what
the robot observes after it, `observe`, `close`, and `report`.

A ``recorder`` (`tamp.rerun_log.RerunRecorder`, an observer) is told of each plan, observation,
phase, move, message and frame; while it records, the simulator calls back at the recorder's
frame period and ``on_frame`` (a video) keeps the period the simulator had when `run` began.
"""

from __future__ import annotations

import dataclasses
import time
from collections import Counter
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from motion.guard import guard_free_move
from motion.ik import IKSolver
from tamp.arm.arm import Arm
from tamp.arm.costs import ArmCosts
from tamp.arm.failures import FailedMove, failed_key
from tamp.camera.from_images import ImageBeliefs
from tamp.loop.config import LoopConfig
from tamp.loop.execute import (
    CollisionMode,
    ExecTools,
    ExecutionResult,
    Fallback,
    execute_move,
    failed_pick,
    motion_check,
    obstacle_boxes,
)
from tamp.loop.faults import draw
from tamp.loop.observe import Observer, camera_goal
from tamp.loop.recover import describe, out_of_reach, tidy
from tamp.loop.report import EpisodeReport, Progress
from tamp.loop.score import MoveScore, Scorer
from tamp.modes import Crisp, Observation
from tamp.outcome import EpisodeInterrupted, EpisodeStatus, Failure, time_limit_reached
from tamp.scene import CAMERA_COLOURS, Pose, SceneError, layout, place_pose
from tamp.sim.base import Simulator
from tamp.sim.factory import make_simulator
from tamp.sim.faults import nudge
from tamp.sim.harness import Harness
from tamp.slots import plan_on_places
from tamp.world.convert.from_poses import Reading, read_state
from task.domains import get_domain
from task.planner import plan
from task.problem import Move, Problem

if TYPE_CHECKING:
    from tamp.rerun_log import RerunRecorder

# what the arm could not do (not a fault of the world): motion-aware planning prices the move out
ARM_FAILURES = frozenset(
    {
        Failure.IK_INFEASIBLE,
        Failure.NO_FREE_SLOT,
        Failure.NO_CLEARANCE,
        Failure.COLLISION,
        Failure.TRACKING,
    }
)


class Episode:
    """One problem in one simulator. ``run()`` returns the EpisodeReport. The blocks start at
    ``poses`` (a scene file's; they must read as ``problem.init``) or, by default, at a
    `tamp.scene.layout` of the problem's initial state drawn with ``seed``."""

    def __init__(
        self,
        problem: Problem,
        config: LoopConfig = LoopConfig(),
        seed: int = 0,
        on_frame: Callable[[Simulator], None] | None = None,
        on_event: Callable[[str], None] | None = None,
        solver: IKSolver | None = None,
        poses: Mapping[str, Pose] | None = None,
        recorder: RerunRecorder | None = None,
    ) -> None:
        self.problem, self.config, self.seed = problem, config, seed
        self.domain = get_domain(problem.domain)
        self.rng = np.random.default_rng(seed)
        self.on_frame = on_frame
        self.recorder = recorder
        self.say = on_event or (lambda text: None)
        if recorder is not None:
            self.say = self._recorded_say(self.say)
        self.solver = solver or IKSolver()
        if poses is None:  # laid out from the problem's initial state
            poses = layout(problem.entities, problem.init, config.scene, seed)
        poses = dict(poses)
        self.status_text = ""
        self.target = problem  # what the robot plans for and tests: the goal it perceives
        perceiver = self.goal_image = None
        if config.observe is Observation.CAMERA:
            if problem.n > CAMERA_COLOURS:
                raise SceneError(
                    f"{problem.n} blocks, but the camera tells at most {CAMERA_COLOURS} apart "
                    "by colour (observe the state instead)"
                )
            perceiver, self.goal_image, self.target = camera_goal(problem, config, seed)
        self.sim = make_simulator(
            config.sim, problem.entities, poses, config.scene, config.grasp, config.camera
        )
        self.sim.truth.lock()  # simulator ground truth only scores episodes
        self.collision = None  # the arm's own collision model: robot geometry + known boxes
        if config.execution.collision is not CollisionMode.OFF:
            from motion.sphere_check import Screened
            from robots.collision import PandaCollision

            # the meshes have the final word; the sphere model screens each phase in one batch
            self.collision = Screened(PandaCollision(config.execution.margin))
        self._acts = 0  # moves attempted: each seeds its motion-planner call differently
        self._avoid: dict = {}  # state -> moves the arm failed there (`ArmCosts` avoid)
        self._failed: list[FailedMove] = []  # the same, by where they failed (`ArmCosts`)
        self.score = Scorer(self.sim.truth, problem, config.scene)
        self.eyes = Observer(self.sim, problem, config, self.rng, self.target, perceiver)
        if self.collision is not None:
            self.eyes.home_guard = self._home_guard
        self._shown = (self.sim.frame_period, 0.0)  # on_frame's (period, next time) when recording
        if recorder is not None:
            recorder.begin(problem.entities, self.sim, self.solver)

    def belief_lines(self) -> list[str]:
        """The last perceived soft state, one line per block (see `Observer.belief_lines`)."""
        return self.eyes.belief_lines()

    def run(self) -> EpisodeReport:
        """Run the episode to the goal or a stop (`play`); closes the simulator (and the
        recorder's file). Torch's thread count is the caller's: ``tamp run`` and the benchmarks
        run an episode on one thread (`tamp.sweep.torch_threads`)."""
        if self.recorder is None:
            return self.play()
        self._shown = (self.sim.frame_period, 0.0)  # on_frame keeps the period set by now
        self.sim.frame_period = self.recorder.period
        report = None
        try:
            report = self.play()
        finally:
            self.recorder.close(report)
        return report

    def play(self) -> EpisodeReport:
        """The closed loop: `start`, then `step` until the goal or a stop; scores the goal on
        ground truth, closes the simulator and returns the `report`."""
        wall0 = time.perf_counter()
        p = None
        try:
            p = self.start()
            while not self.finished(p):
                self.step(p)
            reached = self.score.reached(self.domain)
        except KeyboardInterrupt:
            if p is None:
                raise
            raise self.interrupted(p, wall0) from None
        finally:
            self.close()
        return self.report(p, reached, wall0)

    def interrupted(self, p: Progress, wall0: float) -> EpisodeInterrupted:
        """Ctrl-C: tally ``p`` stopped as ``interrupted`` and reported as it stands, the goal
        scored on ground truth where the world is now (before the simulator closes)."""
        p.stop(EpisodeStatus.INTERRUPTED, f"Ctrl-C after {len(p.moves)} moves")
        return EpisodeInterrupted(self.report(p, self.score.reached(self.domain), wall0))

    def _home_guard(self, way):
        """The trip home to look again, checked against the scene's obstacles (the blocks are
        what the camera failed to see) and rerouted when blocked; None: no safe way."""
        fixed = obstacle_boxes(self.config.scene)
        return guard_free_move(way, self.collision, fixed, self.config.execution.guard, self.seed)

    # --- the public steps ------------------------------------------------------------------
    def start(self) -> Progress:
        """A fresh tally at the problem's initial state. With the camera, the first state is
        read from the first image, not given (a stop when it is unreadable)."""
        init = self.problem.init
        p = Progress(init, self.domain.is_goal(self.target, init))
        if self.config.observe is not Observation.CAMERA:
            return p
        reading = self.observe()
        p.state = reading.state
        if p.state is None:
            p.stop(EpisodeStatus.UNREADABLE, "; ".join(reading.issues))
        return p

    def finished(self, p: Progress) -> bool:
        """The episode stopped, or the observed state satisfies the (perceived) goal."""
        return p.stopped or self.domain.is_goal(self.target, p.state)

    def close(self) -> None:
        """Free the simulator and the collision model."""
        self.sim.close()
        if self.collision is not None:
            self.collision.close()

    def report(self, p: Progress, reached: bool, wall0: float) -> EpisodeReport:
        """The EpisodeReport of tally ``p``: ``reached`` the goal (ground truth), the scored
        contacts, and the ground-truth reads by grant; ``wall0``: the start on perf_counter."""
        planner = "motion-aware" if self.config.planner.lambda_motion > 0 else "soft"
        report = p.report(
            self.problem.name,
            self.config.sim,
            reached,
            self.sim.time,
            wall0,
            planner,
            self.config.observe,
        )
        reads = Counter()
        for (grant, _), n in self.sim.truth.reads.items():
            reads[grant] += n
        return dataclasses.replace(report, touched=dict(self.sim.touched), truth_reads=dict(reads))

    def step(self, p: Progress) -> None:
        """Plan when no move is queued, then execute the next move and check what it did."""
        if not p.queue and not self._next_plan(p):
            return
        if len(p.moves) >= self.config.max_moves:
            p.stop(EpisodeStatus.REPLAN_BUDGET, f"{self.config.max_moves} moves used")
            return
        move = p.queue.pop(0)
        start, expected = p.planned, self.domain.apply_move(self.problem, p.planned, move)
        p.planned = expected
        done = self.execute(p, move)
        if not done.ok and done.failure in ARM_FAILURES:  # motion-aware: priced out next time
            self._avoid.setdefault(start, set()).add(failed_key(move))
            self._remember(move, done)
        self.check(p, move, done, expected)

    def _remember(self, move: Move, done: ExecutionResult) -> None:
        """Keep the failed ``move`` by where it failed (`FailedMove`), from the poses the arm
        sees now (it failed before it moved anything): the pick and the place it was to go
        to; the pick alone when every grasp failed there, or when a move of the block from
        the same spot to another place failed before."""
        if done.path_rad > 0 or self.config.planner.lambda_motion <= 0:
            return  # it ran and failed on the way: nothing says the same move fails again
        poses = self._poses()
        target = place_pose(move, poses, self.config.scene)
        if target is None:
            return
        x = move.entity
        again = any(
            f.entity == x and f.place is not None and f.pick.matches(poses[x].xyz, poses, x)
            for f in self._failed
        )
        self._failed.append(FailedMove.of(x, poses, target.xyz, again or failed_pick(done)))

    def _next_plan(self, p: Progress) -> bool:
        """Plan from the observed state and queue its moves; False when there is none to run
        (no plan: a stop, or with the camera a stalled window that is planned again)."""
        t0 = time.perf_counter()
        basis = self._crisp_basis(p.state)
        result = self._plan_window(basis, self.seed + len(p.plans))
        p.plan_time += time.perf_counter() - t0
        p.plans.append(tuple(str(m) for m in result.plan))
        if self.recorder is not None:
            self.recorder.planned(self.sim, len(p.plans), result)
        if len(p.plans) == 1:
            p.first_solved, p.first_plan = result.solved, result.plan.moves
        window = self.config.observe is Observation.CAMERA and len(result.plan) > 0
        p.stalls = 0 if window or result.solved else p.stalls + 1
        if not (result.solved or window):
            if self.config.observe is Observation.STATE or p.stalls > self.config.max_replans:
                why = result.stats.get("reason")
                if "time_limit" in result.stats:  # the planner's time limit stopped it
                    limit = time_limit_reached(self.config.planner.time_limit_s)
                    why = f"{limit}: {result.stats['time_limit']}"
                p.stop(
                    EpisodeStatus.NO_PLAN, "the planner found no plan" + (f": {why}" if why else "")
                )
            return False
        p.queue, p.planned = list(result.plan), basis
        self.say(f"plan {len(p.plans)}: {len(p.queue)} moves")
        return True

    def _grasps(self) -> tuple[str, ...]:
        """The grasp families the executor has beyond top-down over the highest stack: those of
        its geometric fallback (`tamp.loop.geo_fallback.CHOICES`) when it has one (collision mode
        "plan" and ``execution.geo_fallback``), else none."""
        execution = self.config.execution
        if (
            self.collision is None
            or execution.collision is not CollisionMode.PLAN
            or not execution.geo_fallback
        ):
            return ()
        from tamp.loop.geo_fallback import CHOICES

        return CHOICES

    def _fallback(self) -> Fallback | None:
        """The executor's geometric fallback (`tamp.loop.geo_fallback.GeoFallback` over the
        episode's IK solver and collision model) when it has one (as `_grasps`), else None."""
        execution = self.config.execution
        if (
            self.collision is None
            or execution.collision is not CollisionMode.PLAN
            or not execution.geo_fallback
        ):
            return None
        from tamp.loop.geo_fallback import geo_fallback

        return geo_fallback(self.solver, self.collision, execution.guard)

    def _tools(self) -> ExecTools:
        """What the executor works with: the episode's IK solver, scene, collision model and
        geometric fallback (`_fallback`)."""
        return ExecTools(self.solver, self.config.scene, self.collision, self._fallback())

    def _check_ahead(self, q) -> Callable | None:
        """``check(poses, move)`` for the planner's windows (`LoopConfig.check_ahead`): whether
        `tamp.loop.execute.motion_check` finds the move's motion among ``poses`` (the poses
        the plan predicts) with the arm at ``q`` (where it stands now), nothing run; None
        when the option is off (`LoopConfig` refuses it where it cannot apply)."""
        cfg = self.config
        if not cfg.check_ahead:
            return None
        seed = self.seed * 1000 + 999_983  # the motion planner's seed for checks ahead

        def check(poses, move: Move) -> bool:
            found = motion_check(self._tools(), move, dict(poses), q, cfg.execution, seed)
            return found is None

        return check

    def _crisp_basis(self, observed):
        """The state decoded moves are checked against: the observed one (``crisp="perceived"``,
        the default: a robot has no oracle) or, with ``crisp="true"``, the simulator's true
        state, read through ``GroundTruth.oracle()`` (the observed one if the truth forms no
        state)."""
        if self.config.crisp is not Crisp.TRUE:
            return observed
        with self.sim.truth.oracle():
            poses = self.sim.truth.block_poses()
        truth = read_state(self.problem.entities, poses, self.config.scene).state
        return observed if truth is None else truth

    def _plan_window(self, state, seed: int):
        """Plan from ``state``; with the camera, one window from the current image. Motion-aware
        planning prices each move for the arm (`ArmCosts`) and, with state observation, plans
        on the scene's table places (`tamp.slots`): moves onto the table name their place."""
        current = dataclasses.replace(self.target, init=state)
        costs = None  # motion-aware planning: the arm's cost of each move, from what it sees
        if self.config.planner.lambda_motion > 0:
            poses, scene, q = self._poses(), self.config.scene, self.sim.arm_q()
            if self.config.observe is Observation.STATE:
                arm = Arm(
                    self.solver,
                    q,
                    grasps=self._grasps(),
                    check=self._check_ahead(q),
                    avoid=self._avoid,
                    failed=self._failed,
                )
                planner, reach = self.config.planner, self.config.placements
                return plan_on_places(current, poses, scene, arm, planner, seed, reach=reach)
            arm = Arm(self.solver, q, avoid=self._avoid, failed=self._failed)
            costs = ArmCosts([current], [poses], scene, arm)
        if self.config.observe is Observation.STATE:
            return plan(current, self.config.planner, seed=seed, costs=costs)
        image = self.eyes.image
        mode = dataclasses.replace(self.config.perception, crisp="true")  # checked against init
        beliefs = ImageBeliefs(
            [current], self.eyes.perceiver, lambda i, s: image, [self.goal_image], mode
        )
        window = dataclasses.replace(self.config.planner, max_windows=1)
        return plan(current, window, seed=seed, beliefs=beliefs, costs=costs)

    def execute(self, p: Progress, move: Move) -> ExecutionResult:
        """Execute ``move`` with the injected faults (a drop in transit, a nudge after), let
        the blocks settle, and score it on ground truth (`Scorer.move`): counted in
        ``p.disturbed`` unless clean, and in ``p.unreadable`` too when the true state before or
        after could not be read."""
        inject, k = self.config.inject, len(p.moves)
        drop = draw(self.rng, inject.drop) or k in inject.drop_moves
        drop_at = float(self.rng.uniform(0.2, 0.8)) if drop else None
        before = self.score.state()
        done = self._act(move, f"{move}", drop_at)
        if done.evidence.get("injected"):  # drawn, and the move reached its transit
            p.faults.append(f"drop@{k}")
        nudged = draw(self.rng, inject.nudge) or k in inject.nudge_moves
        if done.ok and nudged:
            nudge(self.sim, move.entity, inject.nudge_m, self.rng)
            p.faults.append(f"nudge@{k}")
        p.moves.append(done)
        self._settle()
        scored = self.score.move(move, before)
        p.disturbed += scored is not MoveScore.CLEAN
        p.unreadable += scored is MoveScore.UNREADABLE
        return done

    def expect(self, state, move: Move):
        """The state ``move`` gives from ``state`` (None when it is illegal there)."""
        if self.domain.check_move(self.target, state, move) is None:
            return self.domain.apply_move(self.target, state, move)
        return None

    def check(self, p: Progress, move: Move, done: ExecutionResult, expected) -> None:
        """Observe the new state (tidying loose blocks if it is unreadable) and decide: go on,
        replan, or stop (robot-side signals only: ``done`` and the observation)."""
        reading = self.observe()
        self.say(f"{move}: " + ("ok" if done.ok else done.failure.value))
        if reading.state is None and p.tidies < self.config.max_tidies:
            p.tidies += 1
            p.moves += tidy(reading, self._act, self._settle, self.say)
            reading = self.observe()
        if reading.state is None:
            p.stop(EpisodeStatus.UNREADABLE, "; ".join(reading.issues))
            return
        p.state = reading.state
        elsewhere = self._elsewhere(move, done)
        if done.ok and p.state == expected and not elsewhere:
            return
        p.queue = []
        p.replans += 1
        why = describe(done) if not done.ok else "the state differs from the plan"
        if done.ok and p.state == expected:  # the plan's later moves assumed the named place
            why = f"{move.entity} went to another table place than the planned {elsewhere}"
        self.say(f"replan {p.replans}: {why}")
        if out_of_reach(p.moves):
            p.stop(EpisodeStatus.OUT_OF_REACH, why)
        elif p.replans > self.config.max_replans:
            p.stop(
                EpisodeStatus.REPLAN_BUDGET,
                f"more than {self.config.max_replans} replans; last: {why}",
            )

    @staticmethod
    def _elsewhere(move: Move, done: ExecutionResult) -> str | None:
        """The table place a move that named one (`tamp.scene.PlacedMove`) was planned to, when
        the executor put the block on another one (``placed_at`` in ``done``'s evidence,
        `tamp.loop.execute.placed_elsewhere`), else None. The plan's later moves were priced
        with the block there, and the slots have different room (a shelf over one takes a
        lower tower), so the rest of the plan no longer holds."""
        if not done.ok or "placed_at" not in done.evidence:
            return None
        at = move.at
        return move.place or f"({at[0]:.2f}, {at[1]:.2f})"

    # --- acting and sensing ----------------------------------------------------------------
    def _act(self, move: Move, label: str, drop_at: float | None = None) -> ExecutionResult:
        """Show ``label`` and execute ``move`` as a pick-and-place."""
        self.status_text = label
        cfg = self.config
        self._acts += 1
        harness = Harness(
            drop_at=drop_at,
            on_frame=self._frames(),
            on_phase=None if self.recorder is None else self.recorder.phase,
        )
        done = execute_move(
            self.sim,
            move,
            self._poses,
            self._tools(),
            cfg.execution,
            seed=self.seed * 1000 + self._acts,
            harness=harness,
        )
        if self.recorder is not None:
            self.recorder.moved(self.sim, label, done)
        return done

    def _settle(self) -> None:
        self.eyes.settle(self._frames())

    def _poses(self) -> dict[str, Pose]:
        return self.eyes.poses(self._frames(), self._show)

    def observe(self) -> Reading:
        """The symbolic state the robot observes now (`Observer.read`)."""
        reading = self.eyes.read(self._frames(), self._show)
        if self.recorder is not None:
            image = self.eyes.image
            support = None if reading.state is None else self.eyes.perceived  # not a stale one
            self.recorder.observed(self.sim, reading, self.target.targets, image, support)
        return reading

    # --- the recorder ----------------------------------------------------------------------
    def _frames(self) -> Callable[[Simulator], None] | None:
        """What the simulator calls back each frame: ``on_frame``, or with a recorder
        `_recorded_frame`."""
        return self.on_frame if self.recorder is None else self._recorded_frame

    def _recorded_frame(self, sim: Simulator) -> None:
        """The recorder's frame, and ``on_frame`` on its own clock (`_shown`)."""
        self.recorder.frame(sim)
        period, due = self._shown
        if self.on_frame is not None and sim.time >= due:
            self.on_frame(sim)
            self._shown = (period, max(due + period, sim.time))

    def _recorded_say(self, say: Callable[[str], None]) -> Callable[[str], None]:
        """``say``, and the message on the recording's time line."""

        def both(text: str) -> None:
            self.recorder.event(self.sim.time, text)
            say(text)

        return both

    def _show(self, text: str) -> None:
        self.status_text = text


def run_episode(problem: Problem, config: LoopConfig = LoopConfig(), seed: int = 0, **kw):
    """Run one episode of ``problem`` (see `Episode`) and return its EpisodeReport."""
    return Episode(problem, config, seed, **kw).run()
