"""Execute a plan from any source, open-loop, and say per step what it did at task and motion level.

A given plan is 4-op PDDL actions in the VAL / Fast Downward format (``(unstack a b)`` per line,
``;`` comments, optional step numbers ``0: (pick-up a)``) or relational moves (``move(a -> b)``,
the form `task.problem.Move` prints, or ``move(a, b)`` or ``a -> b``), read by the project's one
plan reader (`task.symbolic.pddl_io.parse_plan_lines`, which ``tamp validate`` uses too).
Actions pair up into pick-and-place moves (`read_given`). Per step, `GivenPlanEpisode` reports:

- the task-level verdict: do the step's preconditions hold in the TRUE symbolic state (read from
  the simulator for scoring only, `tamp.loop.score`), and which fails (`task.symbolic.strips`);
- the motion-level outcome: executed, or the failure kind and evidence (`tamp.loop.execute`);
- what physically followed: other blocks that moved (fell or were pushed) and where the carried
  block came to rest, from the true poses before and after the step.

A step invalid at task level is still attempted unless ``stop_at_invalid``: an explicit
experimenter grant (``GroundTruth.experimenter()``), under which the experimenter, not the
robot, reads the TRUE state before each step and skips the first step invalid there; the step's
report says so, and the episode's ``truth_reads`` count those reads. With ``replan`` the robot
observes after every step and the planner takes over from the observed state when a step failed
or the observed state is not the one the step should give (robot-side signals only).

The episode drives `tamp.loop.episode.Episode`'s public steps (``execute``, ``check``,
``observe``, ``step``, ``report``), as the closed loop does.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from tamp.loop.config import LoopConfig
from tamp.loop.episode import Episode
from tamp.loop.report import EpisodeReport, Progress
from tamp.outcome import EpisodeInterrupted, EpisodeStatus
from tamp.scene import SceneConfig
from tamp.world.convert.from_poses import read_state
from task import data
from task.domains.blocksworld import moves_to_actions, to_atoms, to_pddl
from task.errors import PDDLError, ProblemError, one_of
from task.problem import TABLE, Action, Move, Problem
from task.symbolic import pddl_io, strips

PICKS, PUTS = ("pick-up", "unstack"), ("put-down", "stack")
MOVED_M = 0.01  # a block other than the carried one that moved this far was disturbed


@dataclass(frozen=True)
class GivenStep:
    """One physical step: a move and the plan entries it came from (a pick and a put, or one
    relational move; ``actions`` is empty for a move). ``move`` is None when the actions do not
    pair, and ``reason`` says why."""

    number: int  # 1-based index of its first action or move in the plan
    label: str
    actions: tuple[Action, ...]
    move: Move | None
    reason: str = ""


@dataclass(frozen=True)
class StepReport:
    """What one given step did (plain values: it goes into report.json as is)."""

    number: int
    label: str
    valid: bool | None  # preconditions hold in the true state (None: the truth forms no state)
    failed: tuple[str, ...]  # the unmet precondition atoms, e.g. "(clear b)"
    reason: str  # why it is invalid at task level ("" when valid)
    attempted: bool
    outcome: str  # "executed", the failure kind, or "not attempted"
    evidence: dict = field(default_factory=dict)
    disturbed: tuple[str, ...] = ()  # other blocks that moved, e.g. "c fell", "d pushed 2.1 cm"
    carried_to: str = ""  # where the carried block came to rest: a block, "table" or "loose"
    # ("" when it never left its place: the move was refused or failed before the lift)

    # who decided not to attempt the step: "experimenter" (the ``stop_at_invalid`` grant, from
    # the true state); "" when it was attempted or its actions do not pair into a move
    skipped_by: str = ""

    def line(self) -> str:
        """One line, e.g. ``3-4 (unstack a d) (stack a b): INVALID at task level: ...``."""
        if self.valid is None:
            verdict = f"task level unknown: {self.reason}"
        else:
            verdict = "valid" if self.valid else f"INVALID at task level: {self.reason}"
        ev = ", ".join(f"{k} {v}" for k, v in self.evidence.items() if not isinstance(v, dict))
        outcome = self.outcome + (f" ({ev})" if ev and self.outcome != "executed" else "")
        attempted = outcome if self.attempted else "no"
        if self.skipped_by:
            attempted += f" ({self.skipped_by} grant --stop-at-invalid: invalid in the true state)"
        text = f"{self.label}: {verdict}; attempted: {attempted}"
        if self.attempted:
            text += f"; disturbed: {', '.join(self.disturbed) or 'none'}"
            rest = "loose" if self.carried_to == "loose" else f"on {self.carried_to}"
            text += f"; carried block: {rest}" if self.carried_to else ""
        return text


def read_given(path: str | Path, problem: Problem) -> tuple[GivenStep, ...]:
    """The steps of a plan file for ``problem``; one-line `TampError` for a missing file, an
    empty plan, a malformed line, an unknown action or block, or a plan for another problem."""
    return parse_given(pddl_io.read_text(path), str(path), problem)


def parse_given(text: str, source: str, problem: Problem) -> tuple[GivenStep, ...]:
    """`read_given` of plan text; ``source`` names it in errors."""
    entries = [(e.lineno, e.step) for e in pddl_io.parse_plan_lines(text, source)]
    if not entries:
        raise PDDLError(f"{source}: the plan is empty (no action or move lines)")
    _check_names(entries, source, problem)
    if isinstance(entries[0][1], Move):
        return tuple(GivenStep(k, f"{k} {e}", (), e) for k, (_, e) in enumerate(entries, start=1))
    return _pair([e for _, e in entries])


def _check_names(entries: list, source: str, problem: Problem) -> None:
    """Unknown action names (per line), blocks not in the problem (all at once), arities."""
    domain, pddl_problem = _pddl(problem)
    unknown = []
    for lineno, e in entries:
        if isinstance(e, Action) and e.name not in PICKS + PUTS:
            raise ProblemError(
                f"{source}: line {lineno}: unknown action {one_of(e.name, PICKS + PUTS)}"
            )
        names = e.args if isinstance(e, Action) else (e.entity,)
        unknown += [x for x in names if x not in problem.entities]
        if isinstance(e, Move) and e.target not in problem.targets:
            unknown.append(e.target)
    if unknown:
        raise ProblemError(
            f"{source}: names blocks not in problem {problem.name}: "
            f"{', '.join(dict.fromkeys(unknown))} (its blocks: {', '.join(problem.entities)}); "
            "is the plan for another problem?"
        )
    for lineno, e in entries:
        if isinstance(e, Action):
            try:
                strips.ground(domain, pddl_problem, e)
            except ProblemError as err:
                raise ProblemError(f"{source}: line {lineno}: {err}") from None


def _pair(actions: list[Action]) -> tuple[GivenStep, ...]:
    """Pick then put of the same block is one move; the first pair that is not ends the plan
    with an unpaired step that says why."""
    steps, i = [], 0
    while i < len(actions):
        a, nxt = actions[i], actions[i + 1] if i + 1 < len(actions) else None
        if a.name not in PICKS:
            why = f"step {i + 1} {a} with an empty hand: expected (pick-up x) or (unstack x y)"
            steps.append(GivenStep(i + 1, f"{i + 1} {a}", (a,), None, why))
            break
        x = a.args[0]
        if nxt is None or nxt.name not in PUTS or nxt.args[0] != x:
            why = (
                f"the plan ends holding {x}"
                if nxt is None
                else f"step {i + 2} {nxt}: the hand holds {x}; expected (put-down {x}) or "
                f"(stack {x} y) (pick and put alternate)"
            )
            label = f"{i + 1}" + (f" {a}" if nxt is None else f"-{i + 2} {a} {nxt}")
            steps.append(GivenStep(i + 1, label, (a,) if nxt is None else (a, nxt), None, why))
            break
        move = Move(x, nxt.args[1] if nxt.name == "stack" else TABLE)
        steps.append(GivenStep(i + 1, f"{i + 1}-{i + 2} {a} {nxt}", (a, nxt), move))
        i += 2
    return tuple(steps)


def _pddl(problem: Problem):
    """The embedded 4-op domain and ``problem`` as PDDL (what actions are grounded against)."""
    domain = data.domain()
    return domain, pddl_io.parse_problem(to_pddl(problem), problem.name, domain)


def verdict(step: GivenStep, problem: Problem, truth, pddl) -> tuple[bool | None, tuple, str]:
    """``(valid, unmet atoms, reason)`` of ``step`` in the true state ``truth`` (None: the true
    poses form no state). A relational move is checked as the 4-op actions it stands for there."""
    if step.move is None:
        return False, (), step.reason
    if truth is None:
        return None, (), "the true scene forms no blocksworld state (a block is loose)"
    actions = step.actions or moves_to_actions(replace(problem, init=truth), [step.move], False)
    state = frozenset(to_atoms(problem, truth))
    for k, action in enumerate(actions):
        ground = strips.ground(*pddl, action)
        unmet = strips.unmet(state, ground)
        if unmet:
            noun, verb = ("precondition", "does") if len(unmet) == 1 else ("preconditions", "do")
            at = f"step {step.number + k} {action}: " if step.actions else f"{action}: "
            return False, unmet, f"{at}{noun} {', '.join(unmet)} {verb} not hold"
        state = strips.apply(state, ground)
    return True, (), ""


# --- the episode ---------------------------------------------------------------------------
class GivenPlanEpisode(Episode):
    """An episode that executes ``steps`` open-loop (see the module docstring); ``run()``
    returns the EpisodeReport with ``steps`` filled in."""

    def __init__(
        self,
        problem: Problem,
        steps: tuple[GivenStep, ...],
        config: LoopConfig,
        seed: int = 0,
        replan: bool = False,
        stop_at_invalid: bool = False,
        **kw,
    ) -> None:
        super().__init__(problem, config, seed, **kw)
        self.steps, self.replan, self.stop_at_invalid = steps, replan, stop_at_invalid
        self.pddl = _pddl(problem)
        self.records: list[StepReport] = []

    def play(self) -> EpisodeReport:
        """The given steps, then (``replan``) the closed loop's `step` until the goal or a
        stop; scores the goal on ground truth, closes the simulator, returns the report."""
        wall0 = time.perf_counter()
        p = Progress(self.problem.init, False)
        p.plans.append(tuple(s.label for s in self.steps))
        if self.recorder is not None:
            self.recorder.given(self.sim, p.plans[0])
        try:
            handed = self._given(p)
            while handed and not self.finished(p):
                self.step(p)
            reached = self.score.reached(self.domain)
        except KeyboardInterrupt:
            stopped = self.interrupted(p, wall0)
            steps = tuple(self.records)
            raise EpisodeInterrupted(replace(stopped.report, steps=steps)) from None
        finally:
            self.close()
        if not (p.stopped or handed or reached):
            bad = [r.label for r in self.records if r.valid is False or r.outcome != "executed"]
            why = f"first problem at {bad[0]}" if bad else "every step executed"
            p.stop(EpisodeStatus.PLAN_ENDED, f"the goal does not hold at the end; {why}")
        return replace(self.report(p, reached, wall0), steps=tuple(self.records))

    def _given(self, p: Progress) -> bool:
        """Run the given steps; True when the planner is to take over (``replan``)."""
        for step in self.steps:
            before = self._true_poses()
            truth = read_state(self.problem.entities, before, self.config.scene).state
            valid, failed, reason = verdict(step, self.problem, truth, self.pddl)
            skipped = self._experimenter_skips(step)
            if step.move is None or skipped:
                by = "experimenter" if skipped else ""
                self._record(
                    StepReport(
                        step.number,
                        step.label,
                        valid,
                        failed,
                        reason,
                        False,
                        "not attempted",
                        skipped_by=by,
                    )
                )
                if not self.replan:
                    who = "the experimenter stopped (--stop-at-invalid) at " if skipped else ""
                    p.stop(EpisodeStatus.INVALID_PLAN, f"{who}{step.label}: {reason}")
                    return False
                return self._observe(p)
            done = self.execute(p, step.move)
            after = self._true_poses()
            x, scene = step.move.entity, self.config.scene
            read0, read1 = (read_state(self.problem.entities, q, scene) for q in (before, after))
            moved = _disturbed(x, (before, after), (read0, read1), self.problem, scene)
            lifted = np.linalg.norm(np.subtract(after[x].xyz, before[x].xyz)) >= MOVED_M
            carried = (
                ""  # refused or failed before the block left its place: nothing was carried
                if not lifted
                else "loose"
                if x in read1.loose or read1.state is None
                else read1.state[self.problem.entities.index(x)]
            )
            outcome = "executed" if done.ok else done.failure.value
            self._record(
                StepReport(
                    number=step.number,
                    label=step.label,
                    valid=valid,
                    failed=failed,
                    reason=reason,
                    attempted=True,
                    outcome=outcome,
                    evidence=dict(done.evidence),
                    disturbed=moved,
                    carried_to=carried,
                )
            )
            if self.replan:  # the robot's own check: observe, and replan on a surprise
                replans = p.replans
                self.check(p, step.move, done, self.expect(p.state, step.move))
                if p.stopped or p.replans > replans:
                    return not p.stopped
        return self.replan and self._observe(p)  # the plan ended: the planner finishes it

    def _experimenter_skips(self, step: GivenStep) -> bool:
        """``stop_at_invalid``: the experimenter, not the robot, decides from the TRUE state
        (an experimenter grant, ``GroundTruth.experimenter()``) that ``step`` is not attempted
        because it is invalid there. The robot never reads the truth: without the grant every
        step that pairs into a move is attempted."""
        if not self.stop_at_invalid or step.move is None:
            return False
        with self.sim.truth.experimenter():
            poses = self.sim.truth.block_poses()
        truth = read_state(self.problem.entities, poses, self.config.scene).state
        return verdict(step, self.problem, truth, self.pddl)[0] is False

    def _observe(self, p: Progress) -> bool:
        """Observe the state the planner takes over from; False if it is unreadable."""
        reading = self.observe()
        if reading.state is None:
            p.stop(EpisodeStatus.UNREADABLE, "; ".join(reading.issues))
            return False
        p.state = reading.state
        p.replans += not self.domain.is_goal(self.target, p.state)
        return True

    def _record(self, record: StepReport) -> None:
        self.records.append(record)
        self.say(record.line())

    def _true_poses(self):
        with self.sim.truth.scoring():
            return self.sim.truth.block_poses()


def _disturbed(carried: str, poses, readings, problem: Problem, scene: SceneConfig):
    """Blocks other than ``carried`` that moved more than `MOVED_M` between the true ``poses``
    (before, after): "fell" when their true support changed (the states of ``readings``), they
    came to rest loose, or they dropped by half a block or more; else "pushed N cm"."""
    (before, after), (read0, read1) = poses, readings
    out = []
    for i, x in enumerate(problem.entities):
        if x == carried:
            continue
        delta = np.subtract(after[x].xyz, before[x].xyz)
        if float(np.linalg.norm(delta)) < MOVED_M:
            continue
        s0, s1 = read0.state, read1.state
        changed = s0 is not None and s1 is not None and s0[i] != s1[i]
        fell = changed or x in read1.loose or delta[2] < -scene.block_size / 2
        out.append(f"{x} fell" if fell else f"{x} pushed {np.linalg.norm(delta) * 100:.1f} cm")
    return tuple(out)
