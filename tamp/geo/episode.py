"""A geometric TAMP episode: observe -> plan -> check -> run -> observe -> replan, in one
simulator, with one of three planners side by side.

Planners (`tamp.modes.GeoPlanner`):

- ``"search-then-check"``: `tamp.geo.baseline.plan_search_then_check`;
- ``"search"``: `tamp.geo.search.plan_search`, the complete best-first search alone;
- ``"motion-aware"``: `tamp.geo.ours.plan_motion_aware` (imported when asked for);
- ``"motion-aware-sampled"``: the same with the goal regions' cells placed by rejection
  sampling at the packer's budget (`tamp.geo.ours.plan_motion_aware_sampled`), an ablation;
- ``"soft"``: task-only planning with execution, today's loop on these problems: a shortest
  symbolic plan ignoring geometry (`tamp.geo.baseline.symbolic_plan`), each move bound to the
  first candidate place of the scene the plan predicts and no grasp chosen; the executor tries
  the top-down grasps only, as the loop's executor does. Expected to fail where geometry
  decides the plan.

The robot observes object poses as `tamp.loop`'s ``observe="state"`` does (the motion-capture
oracle, `tamp.loop.sensors.MocapPoses`: the true poses under the ground truth's ``oracle()``
grant, a sensor by design), or with ``observation="camera"`` estimates them from RGB-D images
of several cameras and the objects' known models (`tamp.camera.scene_poses.ScenePoses`; the
estimates' errors are scored against the ground truth for the record, never acted on), and
reads the facts from them with `OBSERVED` tolerances. Before
each move `check_move` decides it again on the observed scene from the arm's configuration now
(blocked free-space phases rerouted by the motion planner); the move runs
(`tamp.geo.execute.run_move`; above the place the hand looks at the object it holds and
corrects for its slip in the fingers, ``sense``) and the scene is observed again. A move that
fails its check from where the arm stands (IK or a collision; the planner checked it from
home) is checked again from home after a guarded trip there (`AGAIN_FROM_HOME`). A failed
check, a failed run, or observed facts other than those the move was to give end the plan:
the planner plans again from what is observed, up to ``max_replans`` times. Whether the goal
was reached is scored on
the simulator's ground truth under its ``scoring()`` grant, never used to act.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tamp.episode_report import EpisodeReport
from tamp.geo.baseline import plan_search_then_check, symbolic_plan
from tamp.geo.check import Tools, candidate_grasps, check_move, grasp_order
from tamp.geo.config import GeoEpisodeConfig
from tamp.geo.execute import Correction, RunConfig, rests_of, run_move
from tamp.geo.places import candidate_places, fixed_targets
from tamp.geo.search import SearchConfig, plan_search
from tamp.geo.types import TABLE, GeoMove, GeoPlan, GeoStatus, moved
from tamp.modes import GeoPlanner, Observation
from tamp.outcome import EpisodeInterrupted, EpisodeStatus, Failure, time_limit_reached
from tamp.scene import Pose
from tamp.sim.base import Simulator
from tamp.sim.faults import nudge
from tamp.sim.harness import Harness
from tamp.world.geometry import Tolerances
from tamp.world.goal import Goal
from tamp.world.relations import read_facts
from tamp.world.schema import Scene
from task.errors import TampError, member

if TYPE_CHECKING:
    from tamp.rerun_log import RerunRecorder

# settled poses as the motion-capture sensor reads them: `SceneConfig.tol_z`'s 12 mm; an
# object counts as in a region when its footprint crosses the edge by at most 2 mm (a tight
# packing sets boxes flush with the edge, and a placement lands within about a millimetre)
OBSERVED = Tolerances(z=0.012, overlap=0.004, edge=0.002)
SETTLE_S = 0.3  # simulated seconds the objects settle before each observation
# a move the planner checked from home that fails from where the arm stands (its IK seeded
# there, its hand turned as it is) is checked again from home, after a guarded trip there
AGAIN_FROM_HOME = (Failure.IK_INFEASIBLE, Failure.COLLISION)
HOME_TOL = 0.05  # rad, the arm stands at home when every joint is this near


@dataclass(frozen=True)
class MoveRecord:
    """One move attempted: its text, the grasp's name ("" when none was found), ok, and the
    failure (`tamp.outcome.Failure`: a `check_move` failure, a run failure, or ``UNEXPECTED``
    when the observed facts differ from what the move was to give)."""

    move: str
    grasp: str
    ok: bool
    failure: Failure | None = None
    evidence: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        """The record as JSON values (`tamp.episode_report.EpisodeReport`; the evidence as
        it stands: numpy values are the writer's to convert)."""
        return {
            "move": self.move,
            "grasp": self.grasp,
            "ok": self.ok,
            "failure": self.failure.value if self.failure else None,
            "evidence": self.evidence,
        }


Planner = Callable[[Scene, Goal, Tools, SearchConfig], GeoPlan]


def planner_by_name(name: str) -> Planner:
    """The planner called ``name`` (a `GeoPlanner` or its name)."""
    name = member(GeoPlanner, name, "planner")
    if name is GeoPlanner.SEARCH_THEN_CHECK:
        return plan_search_then_check
    if name is GeoPlanner.MOTION_AWARE:
        from tamp.geo.ours import plan_motion_aware

        return plan_motion_aware
    if name is GeoPlanner.MOTION_AWARE_SAMPLED:  # ours, cells placed by rejection sampling
        from tamp.geo.ours import plan_motion_aware_sampled

        return plan_motion_aware_sampled
    if name is GeoPlanner.SOFT:
        return plan_soft
    return plan_search  # GeoPlanner.SEARCH, the last of the five


def plan_soft(scene: Scene, goal: Goal, tools: Tools, config: SearchConfig) -> GeoPlan:
    """Task-only planning: a shortest symbolic plan, each move bound to the first candidate
    place of the predicted scene, nothing checked, no grasp chosen."""
    t0 = time.perf_counter()
    start = tuple(read_facts(scene).supports)
    targets = fixed_targets(scene)
    plan, expanded = symbolic_plan(start, goal, targets, set(), config.symbolic_nodes)
    stats = {"nodes": expanded, "checks": 0, "failures": 0}
    if plan is None:
        stats["time_s"] = time.perf_counter() - t0
        return GeoPlan(GeoStatus.UNSOLVABLE, (), "no symbolic plan", stats)
    world, moves = scene, []
    for obj, target in plan:
        places = candidate_places(world, obj, target, 1, config.seed)
        if not places:
            stats["time_s"] = time.perf_counter() - t0
            return GeoPlan(GeoStatus.FAILED, (), f"no place for {obj} on {target}", stats)
        moves.append(GeoMove(obj, places[0]))
        world = moved(world, obj, places[0].pose)
    stats["time_s"] = time.perf_counter() - t0
    return GeoPlan(GeoStatus.SOLVED, tuple(moves), f"a plan of {len(moves)} moves", stats)


@dataclass(frozen=True)
class PoseNoise:
    """Injected observation noise (the loop's ``noise`` fault, `tamp.loop.faults`): with
    probability ``p`` per pose reading, Gaussian noise of ``sigma`` m on every object's
    position, drawn from ``rng`` (one draw per reading whatever ``p``, so that episodes stay
    aligned across settings)."""

    p: float
    sigma: float
    rng: np.random.Generator

    def __call__(self, poses: dict[str, Pose]) -> dict[str, Pose]:
        """``poses`` as the noisy sensor reads them."""
        if not self.rng.random() < self.p:
            return poses
        noise = self.rng.normal(0.0, self.sigma, size=(len(poses), 3))  # (N, 3)
        return {
            k: Pose(tuple(float(v) for v in np.add(pose.xyz, n)), pose.yaw)
            for (k, pose), n in zip(poses.items(), noise, strict=True)
        }


@dataclass(frozen=True)
class PoseSensor:
    """What the robot reads the object poses with: the motion-capture sensor (``camera``
    None), or a `tamp.camera.scene_poses.ScenePoses` estimating them from its RGB-D images;
    ``noise``: injected noise on every reading (None: none)."""

    camera: object = None
    noise: PoseNoise | None = None

    def read(self, sim: Simulator, scene: Scene) -> dict[str, Pose]:
        """Every object's pose as the sensor reads it now, ``scene``'s poses the camera's
        previous estimates (an object no camera sees keeps its own). The camera's estimates
        are then scored against the ground truth (``scoring()``) for the record only
        (``camera.errors``)."""
        noisy = self.noise or (lambda poses: poses)
        if self.camera is None:
            with sim.truth.oracle():
                return noisy(sim.truth.block_poses())
        from tamp.camera.scene_poses import pose_errors

        poses = self.camera(scene)
        with sim.truth.scoring():
            truth = sim.truth.block_poses()
        self.camera.errors.append(pose_errors(poses, truth, scene))
        return noisy(poses)


def observe(sim: Simulator, scene: Scene, sensor: PoseSensor = PoseSensor()) -> Scene:
    """``scene`` with every object at the pose ``sensor`` reads now."""
    return _with_poses(scene, sensor.read(sim, scene))


def _scored(camera) -> dict:
    """A camera's pose errors over the episode: looks, objects kept unseen (name: looks),
    mean and max position error (mm) and yaw error (deg, cylinders left out); {} for none."""
    if camera is None:
        return {}
    mm = [e[0] for look in camera.errors for e in look.values()]
    deg = [e[1] for look in camera.errors for e in look.values() if e[1] is not None]
    return {
        "looks": camera.looks,
        "unseen": dict(camera.unseen),
        "position_mm_mean": float(np.mean(mm)) if mm else None,
        "position_mm_max": max(mm, default=None),
        "yaw_deg_mean": float(np.mean(deg)) if deg else None,
        "yaw_deg_max": max(deg, default=None),
    }


def _with_poses(scene: Scene, poses: dict[str, Pose]) -> Scene:
    objects = tuple(replace(o, pose=poses[o.name]) for o in scene.objects)
    return replace(scene, objects=objects)


def run_geo_episode(
    scene: Scene,
    goal: Goal,
    config: GeoEpisodeConfig = GeoEpisodeConfig(),
    *,
    tools: Tools | None = None,
    on_event: Callable[[str], None] | None = None,
    recorder: RerunRecorder | None = None,
) -> EpisodeReport:
    """Run ``config.planner`` (a `GeoPlanner`) on ``scene`` toward ``goal`` in simulator
    ``config.sim`` (see the module docstring) with the settings of ``config`` (a
    `GeoEpisodeConfig`: seed, limits, planner budgets, pose sensor, grasp, injected drops,
    video, a PDDL domain for the motion-aware planner). ``tools``: reuse an IK solver and
    collision model (else built and closed here). ``on_event``: called with a line after each
    plan and each move (progress, e.g. for ``tamp run``); what it is told is also in the
    report. ``recorder`` (a `tamp.rerun_log.RerunRecorder`, an observer as the loop's): told of
    every frame (the arm's joints and fingers, the objects' true poses), each observation (the
    facts read), plan, move outcome and message, and closed with the report. Returns the
    `tamp.episode_report.EpisodeReport` both stacks report in: ``status``
    ``GOAL_REACHED`` / ``NOT_REACHED`` (the plans ran out without the goal, or only the robot
    saw it), ``NO_PLAN`` (the planner's status and reason in ``reason``), ``REPLAN_BUDGET`` or
    ``MOVE_BUDGET``; ``reached_goal`` scored on ground truth; one `MoveRecord` per move.
    Ctrl-C raises `EpisodeInterrupted` holding the report so far (status ``INTERRUPTED``).
    Torch's thread count is the caller's: ``tamp run`` and ``tamp bench tamp`` run an
    episode on one thread (`tamp.sweep.torch_threads`)."""
    planner, backend, seed = config.planner, config.sim, config.seed
    observation, domain, video = config.observation, config.domain, config.video
    max_moves, max_replans = config.limits.max_moves, config.limits.max_replans
    say = on_event or (lambda line: None)
    member(Observation, observation, "observation")
    plan_fn = planner_by_name(planner)
    if domain is not None:
        if planner != GeoPlanner.MOTION_AWARE:
            raise TampError(
                f"planner {planner} plans without a PDDL domain; only motion-aware takes one"
            )
        plan_fn = partial(plan_fn, domain=domain)
    search = config.search_config()
    drops, nudges = set(config.drops), set(config.nudges)
    rng = np.random.default_rng(seed)  # the injected faults' draws: nudges' directions, noise
    noise = PoseNoise(config.noise, config.noise_sigma, rng) if config.noise > 0 else None
    nudged: list[int] = []  # the moves after which the object placed was pushed
    wall0 = time.perf_counter()
    own = tools is None
    tools = tools or Tools()
    # execution: the same models, blocked free-space phases rerouted by the motion planner
    runner = Tools(
        tools.solver,
        tools.collision,
        pick_place=tools.pick_place,
        guard=replace(tools.guard, plan=True),
        choices=search.choices,
    )
    if planner == GeoPlanner.SOFT:
        runner.choices = ("top",)  # today's executor: top-down grasps only
    from tamp.geo.sim import open_sim

    sim = open_sim(scene, backend, video=video is not None, grasp=config.grasp)
    sim.truth.lock()
    camera = None
    if observation == Observation.CAMERA:
        from tamp.camera.scene_poses import ScenePoses

        camera = ScenePoses(sim, scene)
    sensor = PoseSensor(camera, noise)
    writer, on_frame = _recorder(video)
    if recorder is not None:
        recorder.begin(tuple(o.name for o in scene.objects), sim, tools.solver)
        on_frame = _recorded(sim, recorder, on_frame)
        say = _recorded_say(sim, recorder, say)
    records: list[MoveRecord] = []
    plan_times, plan_stats = [], []
    plans: list[tuple[str, ...]] = []  # every plan made, as move strings
    first_plan: tuple[GeoMove, ...] = ()  # the first solved plan's moves
    path, replans = 0.0, 0
    status, reason = EpisodeStatus.NOT_REACHED, ""
    try:
        _settle(sim, on_frame)
        world = observe(sim, scene, sensor)
        _believed(sim, recorder, world)
        while True:
            if goal.holds(read_facts(world, OBSERVED)):
                status = EpisodeStatus.GOAL_REACHED
                break
            t0 = time.perf_counter()
            plan = plan_fn(world, goal, tools, search)
            plan_times.append(time.perf_counter() - t0)
            plan_stats.append(dict(plan.stats))
            head = f"plan {len(plan_times)}: {plan.status.value}, {len(plan.moves)} moves"
            why = f" ({plan.reason})" if plan.reason else ""
            say(f"{head} in {plan_times[-1]:.2f} s{why}")
            if recorder is not None:
                recorder.plan_made(sim, head, [m.text() for m in plan.moves], plan_times[-1])
            if not plan.solved:
                status, reason = EpisodeStatus.NO_PLAN, f"{plan.status.value}: {plan.reason}"
                limit = search.max_time_s
                if plan.status is GeoStatus.BUDGET and limit and plan_times[-1] >= limit:
                    reason = f"{time_limit_reached(limit)}; {reason}"
                break
            plans.append(tuple(m.text() for m in plan.moves))
            if not first_plan:
                first_plan = plan.moves
            replan = False
            for move in plan.moves:
                if len(records) >= max_moves:
                    status, reason = EpisodeStatus.MOVE_BUDGET, f"{max_moves} moves used"
                    break
                k, sim0 = len(records), sim.time
                record, world, ran = _act(
                    sim, world, move, runner, seed * 1000 + k, on_frame, k in drops, sensor
                )
                records.append(record)
                if recorder is not None:
                    grasp = f"grasp {record.grasp}" if record.grasp else ""
                    args = (record.failure, record.evidence, grasp, ran, sim.time - sim0)
                    recorder.outcome(sim, record.move, *args)
                _believed(sim, recorder, world)
                say(
                    f"move {k + 1}: {record.move}: "
                    f"{'ok' if record.ok else 'failed: ' + record.failure.value}"
                )
                path += ran
                if not record.ok:
                    replan = True
                    break
                if k in nudges:  # the experimenter pushes the object just placed
                    nudge(sim, move.obj, config.nudge_m, rng)
                    nudged.append(k)
                    _settle(sim, on_frame)
                    before = read_facts(world, OBSERVED).atoms
                    world = observe(sim, world, sensor)
                    _believed(sim, recorder, world)
                    if read_facts(world, OBSERVED).atoms != before:
                        say(f"move {k + 1}: {move.obj} was nudged; the facts changed: replan")
                        replan = True
                        break
            if status is EpisodeStatus.MOVE_BUDGET:
                break
            if replan or not goal.holds(read_facts(world, OBSERVED)):
                replans += 1
                if replans > max_replans:
                    status = EpisodeStatus.REPLAN_BUDGET
                    last = records[-1].failure
                    reason = f"more than {max_replans} replans; last: {last and last.value}"
                    break
        reached = _truly_holds(sim, scene, goal)
    except KeyboardInterrupt:  # Ctrl-C: the report so far, raised as the loop's episode does
        status, reason = EpisodeStatus.INTERRUPTED, f"Ctrl-C after {len(records)} moves"
        reached = _truly_holds(sim, scene, goal)
    except BaseException:
        if recorder is not None:
            recorder.close()
        raise
    finally:
        sim.close()
        if writer is not None:
            writer.close()
        if own:
            tools.close()
    if status is EpisodeStatus.GOAL_REACHED and not reached:
        status = EpisodeStatus.NOT_REACHED
        reason = "the robot saw the goal; the ground truth does not hold it"
    report = EpisodeReport(
        problem=scene.name,
        sim=backend,
        status=status,
        reached_goal=reached,
        moves=tuple(records),
        plans=tuple(plans),
        replans=replans,
        faults=_faults(drops, nudged, len(records)),
        disturbed=0,
        sim_time_s=sim.time,
        wall_time_s=time.perf_counter() - wall0,
        plan_time_s=sum(plan_times),
        initial_plan_solved=bool(first_plan),
        reason=reason,
        first_plan=first_plan,
        touched=dict(sim.touched),
        planner=planner,
        observation=observation,
        plan_times_s=tuple(plan_times),
        plan_stats=tuple(plan_stats),
        arm_path_rad=path,
        pose_errors=_scored(camera),
    )
    if recorder is not None:
        recorder.close(report)
    if status is EpisodeStatus.INTERRUPTED:
        raise EpisodeInterrupted(report)
    return report


def _faults(drops: set[int], nudged: list[int], moves: int) -> tuple[str, ...]:
    """The injected faults as the loop reports them, in move order: ``drop@K`` for each move
    ``K`` run with a drop, ``nudge@K`` for each object pushed after move ``K``."""
    hit = [(k, "drop") for k in drops if k < moves] + [(k, "nudge") for k in nudged]
    return tuple(f"{kind}@{k}" for k, kind in sorted(hit))


def _truly_holds(sim: Simulator, scene: Scene, goal: Goal) -> bool:
    """Whether ``goal`` holds in the simulator's ground truth (scoring only)."""
    with sim.truth.scoring():
        truth = _with_poses(scene, sim.truth.block_poses())
    return goal.holds(read_facts(truth, OBSERVED))


def _act(
    sim,
    world: Scene,
    move: GeoMove,
    runner: Tools,
    seed: int,
    on_frame,
    drop: bool,
    sensor: PoseSensor = PoseSensor(),
):
    """Check ``move`` on the observed ``world`` from the arm's configuration now, run it,
    settle and observe with ``sensor``: (record, observed scene, joint path run in rad)."""
    o = world.object(move.obj)
    grasps = None
    if move.grasp is None:
        grasps = grasp_order(world, o, candidate_grasps(o, runner.choices))
    verdict = check_move(world, move, runner, grasps=grasps, q_now=sim.arm_q(), seed=seed)
    home = 0.0  # rad run on the way home
    if not verdict.ok and verdict.failure in AGAIN_FROM_HOME:
        home = _go_home(sim, world, runner, on_frame)
        if home:
            verdict = check_move(world, move, runner, grasps, q_now=sim.arm_q(), seed=seed)
    if not verdict.ok:
        return MoveRecord(move.text(), "", False, verdict.failure, verdict.evidence), world, home
    support = dict(read_facts(world, OBSERVED).supports).get(move.obj, TABLE)
    rests = rests_of(world, move, support)
    # the prior of the camera's estimates: where the objects should be, the moved one at its
    # place (objects of one colour are told apart by nearness to it); motion capture replaces
    # every pose alike
    expected = moved(world, move.obj, move.place.pose)
    ran = run_move(
        sim,
        move,
        verdict,
        rests,
        RunConfig(),
        Harness(drop_at=0.5 if drop else None, on_frame=on_frame),
        Correction(
            sense=lambda: np.asarray(sensor.read(sim, expected)[move.obj].xyz),
            solver=runner.solver,
            screen=partial(_free, world, move, verdict.grasp, rests[0], runner),
        ),
    )
    _settle(sim, on_frame)
    seen = observe(sim, expected, sensor)
    name = verdict.grasp.name
    path = home + ran.path_rad
    if not ran.ok:
        return MoveRecord(move.text(), name, False, ran.failure, ran.evidence), seen, path
    want = read_facts(moved(world, move.obj, move.place.pose), OBSERVED).atoms
    got = read_facts(seen, OBSERVED).atoms
    if want != got:
        # what the run itself noticed (re-grasps on release, corrections) stays beside it
        evidence = {**ran.evidence, "missing": sorted(want - got), "extra": sorted(got - want)}
        return MoveRecord(move.text(), name, False, Failure.UNEXPECTED, evidence), seen, path
    return MoveRecord(move.text(), name, True, None, ran.evidence), seen, path


def _free(world: Scene, move: GeoMove, grasp, support: str, runner: Tools, phases) -> bool:
    """Whether ``phases`` (a corrected place side: ``shift``, ``lower``, ``open``, ``retreat``)
    pass the guard's collision check in ``world`` (the shift as a transit), not rerouted;
    ``support``: what the object left, as `tamp.geo.check.support_box` names it."""
    from motion.guard import guard_pick_place
    from tamp.geo.check import pick_place_world

    named = tuple(replace(p, name="transit") if p.name == "shift" else p for p in phases)
    where = pick_place_world(world, world.object(move.obj), move, grasp, support)
    return guard_pick_place(named, runner.collision, where, replace(runner.guard, plan=False)).ok


def _go_home(sim: Simulator, world: Scene, runner: Tools, on_frame=None) -> float:
    """Take the empty hand home (`PANDA.q_home`, where the planner checked its moves from)
    along a guarded free move (`motion.guard.guard_free_move`, rerouted when blocked): the
    joint path run (rad), 0 when it already stood there (within `HOME_TOL` rad) or no safe
    way was found."""
    from motion.guard import guard_free_move
    from motion.trajectory import TRANSIT, straight_segment
    from robots.panda import PANDA
    from tamp.geo.check import boxes

    q = sim.arm_q()
    if np.abs(q - PANDA.q_home).max() <= HOME_TOL:
        return 0.0
    way = straight_segment(q, PANDA.q_home, sim.dt, PANDA, TRANSIT)
    run = guard_free_move(way, runner.collision, boxes(world), runner.guard)
    if run is None:
        return 0.0
    sim.run(run, "open", on_frame=on_frame)
    return float(np.linalg.norm(np.diff(run.positions, axis=0), axis=1).sum())


def _settle(sim: Simulator, on_frame) -> None:
    from motion.trajectory import JointTrajectory

    hold = JointTrajectory.hold(sim.arm_q(), SETTLE_S, sim.dt)
    sim.run(hold, "open", on_frame=on_frame)


def _believed(sim: Simulator, recorder, world: Scene) -> None:
    """Tell ``recorder`` (None: no recording) the facts read from the observed ``world``."""
    if recorder is None:
        return
    facts = read_facts(world, OBSERVED)
    lines = facts.text().splitlines() + [f"unexplained: {issue}" for issue in facts.issues]
    recorder.facts(sim, lines)


def _recorded(sim: Simulator, recorder, on_frame):
    """What ``sim`` calls back each frame while ``recorder`` records: the recorder's frame at
    its period, and ``on_frame`` (a video's, or None) on its own clock, every
    ``sim.frame_period`` simulated seconds as it stood (the loop's `_recorded_frame`)."""
    period, due = sim.frame_period, [0.0]
    sim.frame_period = recorder.period

    def frame(s: Simulator) -> None:
        recorder.frame(s)
        if on_frame is not None and s.time >= due[0]:
            on_frame(s)
            due[0] = max(due[0] + period, s.time)

    return frame


def _recorded_say(sim: Simulator, recorder, say: Callable[[str], None]):
    """``say``, and the message on the recording's time line."""

    def both(text: str) -> None:
        recorder.event(sim.time, text)
        say(text)

    return both


def _recorder(video: str | Path | None):
    """(EpisodeVideo, on_frame) writing every frame to ``video``, or (None, None)."""
    if video is None:
        return None, None
    from tamp.video import EpisodeVideo

    recorder = EpisodeVideo(video)

    def on_frame(sim: Simulator) -> None:
        recorder.write(sim)

    return recorder, on_frame
