"""Run one checked pick-and-place in a simulator and tell from the robot's own signals how it
went: the geometric room's counterpart of `tamp.loop.execute`.

The phases come from `tamp.geo.check.check_move` on the observed scene (the arm's start
configuration read from the simulator). Each phase tells the simulator which contacts it is
meant to make (`tamp.sim.base.Expected`: the hand on the object it handles; the held object on
what it leaves while lifted and on what it goes onto while lowered), so the experimenter's
contact scoring (``Simulator.touched``) counts every other touch. Failures are read from the
gripper as a real robot reads them: after closing, the fingers must stand at the grasp's width
(within ``width_tol``) pushed on both sides (``grasp_missed``); after the lift and the transit
they must still stand at that width (``dropped``); a joint tracking error beyond
``max_tracking`` means the arm was blocked (``tracking_error``): the failure kinds are
`tamp.outcome.Failure`'s, the loop executor's. After a failure at the object
the hand opens and backs out along its descent. After the release the fingers must stand open
(their opening within ``width_tol`` of the stroke): an object that turned a little in the
fingers on the way can stay wedged between the open pads (PyBullet: a pad's edge sunk a
millimetre into it; the retreat then carries it off and drops it anywhere, once on a post's
top), so the hand closes on it again and reopens, at most ``release_tries`` times, and then
turns the wrist a little each way and back with the fingers open (``wiggles``: twice in
PyBullet a pad stayed sunk after both re-grasps, sorting variant 11), before it retreats; the
run's evidence says how often (``regrasped``, ``wiggled``), or that it stayed stuck
(``not_released``). The back-off after a missed grasp frees the object the same way (the
fingers had closed on it askew) before it backs up. Nothing here reads ground truth.

Where the place is tight, a held object that slipped a few millimetres in the fingers (the
friction grasp, most in MuJoCo) would land out of its cell. Given a ``sense`` of the held
object's position (the motion-capture sensor the episode observes with) and the IK
``solver``, the hand stops above the place, looks, and when the object is more than
`RunConfig.correct_min` off (and at most ``correct_max``) moves by the error before lowering
(`motion.pick_place.corrected_place`: phases ``shift``, ``lower``, ``open``, ``retreat``);
the run's evidence says by how much (``corrected_mm``). The object slips on the way down too
(MuJoCo: 2 mm over a 30 cm lower, enough to set a place flush with a kerb onto the kerb), so
the hand stops again `RunConfig.low_look` above the release (`motion.pick_place.split_lower`),
looks and corrects the rest the same way (``corrected_low_mm``; the small shift checked as
part of the lowering). A correction the ``screen`` refuses is not run (``uncorrected_mm``,
``uncorrected_low_mm``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from motion.pick_place import Phase, corrected_place, split_lower
from motion.trajectory import JointTrajectory, straight_segment
from robots.panda import PANDA
from tamp.geo.check import MoveCheck, support_box
from tamp.geo.types import GeoMove
from tamp.outcome import Failure
from tamp.sim.base import Expected, Simulator, lost_hold
from tamp.sim.harness import Harness

if TYPE_CHECKING:
    from motion.ik import IKSolver


@dataclass(frozen=True)
class RunConfig:
    """Thresholds of the failure checks (`tamp.loop.execute.ExecConfig`'s values)."""

    width_tol: float = 0.007  # m: a held object keeps the fingers at the grasp's width +- this
    min_force: float = 0.2  # N: both fingers push at least this on a freshly closed grasp
    max_tracking: float = 0.3  # rad: beyond this the arm is blocked
    correct_min: float = 0.0005  # m: a held object this far off the plan above the place: moved
    correct_max: float = 0.02  # m: ... unless farther off than this (then it runs as planned)
    look_s: float = 0.3  # s: the hand holds still above the place this long before looking
    low_look: float = 0.02  # m: ... and again this far above the release, before the last bit
    release_tries: int = 2  # closings on an object still between the opened fingers
    reclose_s: float = 0.25  # s: the gripper's closing time (`PickPlaceConfig.close_time`)
    # ... then turns of the wrist (the last joint, rad, each and back) with the fingers open:
    # a pad's edge sunk into an object that turned in the fingers comes out sideways
    wiggles: tuple[float, ...] = (0.03, -0.03, 0.06, -0.06)


@dataclass(frozen=True)
class MoveRun:
    """What running one move did: ``ok`` or the ``failure`` (`Failure`: ``GRASP_MISSED``,
    ``DROPPED``, ``TRACKING``) with ``evidence``; simulated seconds, joint path run (rad: the sum of
    |dq| over the phases started) and wall seconds."""

    ok: bool
    failure: Failure | None = None
    evidence: dict = field(default_factory=dict)
    sim_time_s: float = 0.0
    path_rad: float = 0.0
    wall_s: float = 0.0


def expected_contacts(phase: str, obj: str, rests: tuple[str, str]) -> Expected:
    """The contacts ``phase`` of the move of ``obj`` is meant to make: the hand on ``obj``
    throughout; once held, ``obj`` on what it leaves (lift) and what it goes onto (lower),
    ``rests`` = (from, onto) as the simulator names them, nothing in transit."""
    during = {"lift": rests[0], "transit": None, "shift": None, "lower": rests[1]}
    if phase not in during:
        return Expected(obj)
    return Expected(obj, obj, frozenset({during[phase]} - {None}))


@dataclass(frozen=True)
class Correction:
    """How a run corrects the place for the held object's slip in the hand (module
    docstring): ``sense``, the held object's centre (3,) as a sensor reads it now; ``solver``
    (`motion.ik.IKSolver`), the corrected phases' IK; ``screen``, whether corrected phases are
    free of collisions (the guard's check; None: not checked): corrected phases it refuses
    are not run, the planned ones are."""

    sense: Callable[[], np.ndarray]
    solver: IKSolver
    screen: Callable[[tuple[Phase, ...]], bool] | None = None


def run_move(
    sim: Simulator,
    move: GeoMove,
    check: MoveCheck,
    rests: tuple[str, str],
    config: RunConfig = RunConfig(),
    harness: Harness = Harness(),
    correction: Correction | None = None,
) -> MoveRun:
    """Run ``check``'s phases (a feasible `MoveCheck` of ``move``) in ``sim``; ``rests``: what
    the object leaves and goes onto (`support_box` names). ``harness.drop_at`` in [0, 1] opens
    the gripper at that fraction of the transit (fault injection), ``harness.on_frame`` is
    called at every frame (`tamp.sim.harness.Harness`). ``correction``: correct the place for
    the object's slip in the hand (`Correction`); None: run as planned."""
    on_frame, drop_at = harness.on_frame, harness.drop_at
    wall0, sim0, path = time.perf_counter(), sim.time, 0.0
    width = check.grasp.width
    evidence: dict = {}

    def done(failure: Failure | None = None, **found) -> MoveRun:
        return MoveRun(
            failure is None,
            failure,
            {**evidence, **found},
            sim_time_s=sim.time - sim0,
            path_rad=path,
            wall_s=time.perf_counter() - wall0,
        )

    corrected = _Looks(sim, move, correction, config, on_frame, evidence).corrected
    handling = Expected(move.obj)
    phases, looks, low = list(check.motion), 0, None
    looking = correction is not None
    while phases:
        phase = phases.pop(0)
        if looking and phase.name == "lower" and looks == 0:  # above the place
            looks = 1
            phase, phases = corrected(phase, phases, low=False)
        if looking and phase.name == "lower" and looks == 1:  # stop short of the release
            looks = 2
            split = split_lower(correction.solver, phase, config.low_look)
            if split is not None:
                phase, low = split
                phases.insert(0, low)
        elif looking and phase is low:  # look again there: what slipped on the way down
            low = None
            phase, phases = corrected(phase, phases, low=True)
        release = None
        if phase.name == "transit" and drop_at is not None:
            release = drop_at * phase.trajectory.duration
        if phase.name == "open":
            sim.detach()
        q = phase.trajectory.positions  # (S, J)
        path += float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())
        expected = expected_contacts(phase.name, move.obj, rests)
        worst = sim.run(phase.trajectory, phase.gripper, release, on_frame, expected)
        if worst > config.max_tracking:
            freed = _back_off(sim, check.motion, on_frame, move.obj, rests, config)
            return done(Failure.TRACKING, phase=phase.name, error_rad=round(worst, 3), **freed)
        if phase.name == "open":
            closing = expected_contacts("lower", move.obj, rests)
            evidence |= _release(sim, config, on_frame, closing, phase.trajectory.duration)
        lost = lost_hold(sim, phase.name, width, config, on_frame, handling, _no_object)
        if lost is not None and lost[0] is Failure.GRASP_MISSED:
            freed = _back_off(sim, check.motion, on_frame, move.obj, rests, config)
            return done(Failure.GRASP_MISSED, **lost[1], **freed)
        if lost is not None:
            return done(Failure.DROPPED, after=phase.name, injected=release is not None, **lost[1])
    return done()


@dataclass(frozen=True)
class _Looks:
    """`run_move`'s looks at the held object on the way down, with what it needs; each
    look's correction (or its refusal) noted in ``evidence``."""

    sim: Simulator
    move: GeoMove
    correction: Correction
    config: RunConfig
    on_frame: Callable | None
    evidence: dict

    def corrected(self, phase: Phase, rest: list, low: bool) -> tuple[Phase, list]:
        """Look at the held object before ``phase`` (a lower) and correct the place side."""
        sim, move, correction, config = self.sim, self.move, self.correction, self.config
        fixed = _look_and_correct(sim, move, phase, rest, correction, config, self.on_frame)
        if fixed is not None and low:  # the shift is a step of the lowering, beside the place
            fixed = (
                tuple(replace(p, name="lower") if p.name == "shift" else p for p in fixed[0]),
                fixed[1],
            )
        key = "low" if low else ""
        screen = correction.screen
        if fixed is not None and screen is not None and not screen(fixed[0]):
            self.evidence[f"uncorrected{key and '_' + key}_mm"] = fixed[1]  # it would collide
            fixed = None
        if fixed is None:
            return phase, rest
        self.evidence[f"corrected{key and '_' + key}_mm"] = fixed[1]
        return fixed[0][0], list(fixed[0][1:])


def _no_object(sim: Simulator) -> dict:
    """A welded grasp's miss: no object between the fingers (`lost_hold`'s evidence)."""
    return {"weld": "no object between the fingers"}


def rests_of(scene, move: GeoMove, support: str) -> tuple[str, str]:
    """(what the object leaves, what it goes onto) as the simulator names the bodies."""
    return support_box(scene, support), support_box(scene, move.place.target)


def _look_and_correct(
    sim,
    move: GeoMove,
    lower: Phase,
    rest: list,
    correction: Correction,
    config: RunConfig,
    on_frame,
):
    """Hold above the place, read where the held object is and, when it is off the plan by
    more than ``correct_min`` (at most ``correct_max``), the corrected place side: (phases
    replacing ``lower`` and ``rest``, the error in mm), else None."""
    q = sim.arm_q()
    hold = JointTrajectory.hold(q, config.look_s, sim.dt)
    sim.run(hold, "closed", on_frame=on_frame, expected=Expected(move.obj, move.obj))
    seen = np.asarray(correction.sense(), dtype=np.float64)
    solver = correction.solver
    # the object's offset from the TCP in the plane, as planned at the place and as seen now
    # (a top grasp plans it at 0; a tilted one beside the TCP); the hand moves by the difference
    place_tcp, tcp_now = solver.fk(np.stack([lower.trajectory.positions[-1], sim.arm_q()]))
    planned = np.asarray(move.place.xyz[:2]) - place_tcp[:2, 3]
    error = planned - (seen[:2] - tcp_now[:2, 3])  # (2,) m
    off = float(np.linalg.norm(error))
    if not config.correct_min < off <= config.correct_max:
        return None
    tail = corrected_place(solver, sim.arm_q(), (lower, *rest), error)
    if tail is None:
        return None
    return tail, round(off * 1000, 1)


def opened(sim: Simulator, config: RunConfig) -> dict | None:
    """None when the fingers stand open (their opening within ``config.width_tol`` of the
    stroke); else the gripper's reading."""
    r = sim.gripper()
    if r.width >= 2 * PANDA.finger_open - config.width_tol:
        return None
    return {
        "finger_width": round(r.width, 4),
        "left_force": round(r.left_force, 3),
        "right_force": round(r.right_force, 3),
    }


def _release(sim, config: RunConfig, on_frame, closing: Expected, open_s: float) -> dict:
    """After the hand opened on an object (``closing.handled``): while the fingers do not
    stand open (`opened`), the object wedged between them, close on it (the contacts
    ``closing`` expects) and open again for ``open_s`` s, the hand where it stands, at most
    ``config.release_tries`` times; then turn the wrist a little each way and back
    (``config.wiggles``) until they do. The evidence: ``regrasped`` (closings), ``wiggled``
    (turns), and ``not_released`` (the last reading) when the fingers never opened."""
    stuck, tries = opened(sim, config), 0
    while stuck is not None and tries < config.release_tries:
        tries += 1
        q = sim.arm_q()
        close = JointTrajectory.hold(q, config.reclose_s, sim.dt)
        sim.run(close, "closed", on_frame=on_frame, expected=closing)
        reopen = JointTrajectory.hold(q, open_s, sim.dt)
        sim.run(reopen, "open", on_frame=on_frame, expected=Expected(closing.handled))
        stuck = opened(sim, config)
    out = {"regrasped": tries} if tries else {}
    wiggled = 0
    for turn in config.wiggles if stuck is not None else ():
        wiggled += 1
        q = sim.arm_q()
        turned = q.copy()
        turned[-1] += turn
        touching = Expected(closing.handled)
        for a, b in ((q, turned), (turned, q)):  # turn, open there, turn back
            sim.run(straight_segment(a, b, sim.dt), "open", on_frame=on_frame, expected=touching)
        stuck = opened(sim, config)
        if stuck is None:
            break
    if wiggled:
        out["wiggled"] = wiggled
    return out if stuck is None else {**out, "not_released": stuck}


def _back_off(
    sim: Simulator, phases: tuple[Phase, ...], on_frame, obj: str, rests, config: RunConfig
) -> dict:
    """After a failure at the object ``obj``: open the gripper, free the object where it
    stays wedged between the fingers (`_release`: a grasp that missed had closed on it
    askew), and undo the descent. Returns `_release`'s evidence."""
    sim.detach()
    q = sim.arm_q()
    expected = Expected(obj)
    sim.run(JointTrajectory.hold(q, 0.3, sim.dt), "open", on_frame=on_frame, expected=expected)
    closing = Expected(obj, obj, frozenset(rests))
    freed = _release(sim, config, on_frame, closing, 0.3)
    down = next(ph for ph in phases if ph.name == "descend").trajectory
    back = JointTrajectory(
        down.times, down.positions[::-1].copy(), -down.velocities[::-1], down.accelerations[::-1]
    )
    if np.abs(back.positions[0] - q).max() < 0.05:
        sim.run(back, "open", on_frame=on_frame, expected=expected)
    return freed
