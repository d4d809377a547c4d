"""The generic soft lift of a grounded STRIPS problem: the planner of any PDDL domain no file
is written for, and the oracle the hand-written domains are tested against.

A problem is grounded by relaxed reachability (`task.symbolic.ground.reachable`; PDDLError
naming any feature beyond STRIPS). Atoms no reachable ground action adds or deletes are
*static*: they hold in every reachable state, so they leave preconditions and tensors. The
rest are the P *fluent* atoms, the columns of a single state row (``entities = ("state",)``,
``fixed`` = the fluent atoms as strings, ``goal`` = ``("state", atom)`` for each fluent goal
atom). A crisp state is the frozenset of fluent atoms that hold (static atoms may be included:
they are ignored); a move is the ground `task.problem.Action` itself, so ``to_actions`` is the
identity. The grounded arrays are `task.symbolic.strips_task`; the tensors and goal terms
`task.domains.strips_soft`; the relaxations `task.symbolic.relaxed`.
``lower_bound`` is LM-cut (admissible; it marks dead ends) and ``estimate`` h_FF: the decoder
ranks restarts by moves + estimate. With h_max or the goal count most windows tie, so the
fewest moves win (Logistics dev instances 201-286: 2 of 11 solved with h_max, 11 of 11 with
LM-cut); h_FF tracks progress more closely still (see BENCHMARKS.md).

The parsed PDDL domain and problem stay in ``problem.data``: ``to_pddl`` writes the problem
back (`pddl.formatter`), ``pddl_domain_text(problem)`` its domain; the lift has no domain of
its own, so ``pddl_domain_text()`` without a problem raises ProblemError.
"""

from __future__ import annotations

import contextlib
import random
from collections.abc import Iterator, Sequence
from types import MappingProxyType

from pddl.core import Domain as PDDLDomain
from pddl.core import Problem as PDDLProblem

from task.deadline import NO_DEADLINE, Deadline
from task.domains import strips_soft
from task.domains.base import DomainBase, zero_cycle_loss
from task.errors import PDDLError, ProblemError
from task.problem import Action, Problem
from task.symbolic import relaxed, strips
from task.symbolic.strips import Atom, GroundAction
from task.symbolic.strips_task import StripsTask

NAME = "strips"
State = frozenset[Atom]


# ------------------------------------------------------------------------------------- PDDL


def from_pddl(
    domain: PDDLDomain,
    problem: PDDLProblem,
    order: Sequence[str] = (),
    deadline: Deadline = NO_DEADLINE,
) -> Problem:
    """Ground ``problem`` and lift it. PDDLError for what is not STRIPS (negative
    preconditions, conditional or universal effects, numeric fluents, derived predicates),
    ProblemError for a goal atom that no sequence of actions reaches; `TimeLimitReached` when
    ``deadline`` (a command's) passes while grounding."""
    from task.symbolic.ground import reachable

    grounding = reachable(domain, problem, deadline)
    reached = set(grounding.atoms)
    goal = strips.goal_atoms(problem)
    missing = [a for a in goal if a not in reached]
    if missing:
        raise ProblemError(
            f"problem {problem.name}: goal {strips.atom_str(missing[0])} is unreachable"
        )
    task = StripsTask.build(grounding.actions, goal, domain, problem, order)
    return Problem(
        name=str(problem.name),
        domain=NAME,
        entities=("state",),
        init=(),
        goal=tuple(("state", strips.atom_str(a)) for a in task.goal),
        fixed=tuple(strips.atom_str(a) for a in task.atoms),
        data=task,
    )


def problem_from_text(domain_text: str, problem_text: str, source: str = "<problem>") -> Problem:
    """`from_pddl` of PDDL texts (PDDLError naming ``source`` on a parse error)."""
    from task.symbolic import pddl_io

    domain = pddl_io.parse_domain(domain_text, f"{source} (domain)")
    problem = pddl_io.parse_problem(problem_text, source, domain)
    return from_pddl(domain, problem, pddl_io.object_order(problem_text))


def to_pddl(problem: Problem) -> str:
    """The problem's PDDL text (written back from the parsed problem it was built from)."""
    from pddl.formatter import problem_to_string

    return problem_to_string(_task(problem).pddl_problem)


def pddl_domain_text(problem: Problem | None = None) -> str:
    """The domain text of ``problem``; the generic lift has no domain of its own."""
    if problem is None:
        raise ProblemError(
            "the generic STRIPS lift has no domain file of its own: "
            "pass the problem (pddl_domain_text(problem)) or use the problem's PDDL domain"
        )
    from pddl.formatter import domain_to_string

    return domain_to_string(_task(problem).pddl_domain)


def to_atoms(problem: Problem, state: State) -> frozenset[Atom]:
    """The PDDL atoms that hold in ``state``: its fluent atoms plus the static ones."""
    return frozenset(state) | _task(problem).static


# ------------------------------------------------------------------------------------ crisp


def _task(problem: Problem) -> StripsTask:
    if not isinstance(problem.data, StripsTask):
        raise ProblemError(f"problem {problem.name} was not built by the strips lift (from_pddl)")
    return problem.data


def _ground(problem: Problem, move: Action) -> GroundAction | None:
    """The ground action of ``move``: None when it is well formed but never reachable.
    ProblemError for an unknown action name, object, arity or type."""
    task = _task(problem)
    j = task.index.get(Action(move.name.lower(), tuple(a.lower() for a in move.args)))
    if j is not None:
        return task.effects[j]
    with contextlib.suppress(PDDLError):  # a schema `strips` cannot ground (equality)
        strips.ground(task.pddl_domain, task.pddl_problem, move)
    return None


def initial_state(problem: Problem) -> State:
    return _task(problem).init


def check_move(problem: Problem, state: State, move: Action) -> str | None:
    """None if ``move`` applies in ``state``, else the unmet preconditions in one line."""
    action = _ground(problem, move)
    if action is None:
        return "its preconditions hold in no state reachable from the initial state"
    unmet = strips.unmet(state, action)
    if not unmet:
        return None
    noun, verb = ("precondition", "does") if len(unmet) == 1 else ("preconditions", "do")
    return f"{noun} {', '.join(unmet)} {verb} not hold"


def apply_move(problem: Problem, state: State, move: Action) -> State:
    """The successor (delete, then add); ProblemError if ``move`` does not apply."""
    reason = check_move(problem, state, move)
    if reason is not None:
        raise ProblemError(f"illegal {move}: {reason}")
    return strips.apply(state, _ground(problem, move))


def to_actions(problem: Problem, moves: Sequence[Action], strict: bool = True) -> tuple:
    """The moves as they are (they are PDDL actions); ``strict`` replays them from the
    initial state and raises ProblemError on the first that does not apply."""
    state = initial_state(problem)
    for move in moves:
        if strict:
            state = apply_move(problem, state, move)
        else:
            _ground(problem, move)  # unknown names raise either way
    return tuple(moves)


def legal_moves(problem: Problem, state: State) -> list[Action]:
    task = _task(problem)
    return [a for a, e in zip(task.actions, task.effects, strict=True) if e.pre_pos <= state]


def is_goal(problem: Problem, state: State) -> bool:
    return all(a in state for a in _task(problem).goal)


def decode(problem: Problem, row: int, col: int, n: int) -> Action | None:
    """Action column ``col`` of the single row: the col-th ground action (None: padding)."""
    actions = _task(problem).actions
    return actions[col] if row == 0 and col < len(actions) else None


def lower_bound(problem: Problem, state: State) -> float:
    """Admissible: max(LM-cut, ceil(unmet goal atoms / most goal atoms one action adds));
    INF at a dead end (the delete relaxation cannot reach some goal atom). Memoised."""
    task, key = _task(problem), frozenset(state)
    if key not in task.bounds:
        unmet = sum(a not in key for a in task.goal)
        count = float(-(-unmet // max(task.goal_adds, 1)))
        if len(task.bounds) > 100_000:
            task.bounds.clear()
        task.bounds[key] = max(relaxed.lm_cut(task, key), count) if unmet else 0.0
    return task.bounds[key]


def _relaxed(problem: Problem, state: State) -> tuple[float, tuple[int, ...]]:
    """h_FF of ``state`` and its helpful action columns (`task.symbolic.relaxed`), memoised
    with the bounds (0 and none at a goal; INF and none at a dead end)."""
    task, key = _task(problem), ("ff", frozenset(state))
    if key not in task.bounds:
        if is_goal(problem, state):
            task.bounds[key] = (0.0, ())
        else:
            chosen = relaxed.relaxed_plan(task, key[1])
            if chosen is None:
                task.bounds[key] = (relaxed.INF, ())
            else:
                task.bounds[key] = (float(len(chosen)), relaxed.helpful(task, key[1], chosen))
    return task.bounds[key]


def estimate(problem: Problem, state: State) -> float:
    """h_FF (`task.symbolic.relaxed.ff`), not admissible: what the decoder ranks restarts by
    (moves + estimate) and the greedy fallback search (`task.symbolic.lazy_search.lazy_greedy`)
    is guided by; LM-cut still marks dead ends. Memoised with the bounds."""
    return _relaxed(problem, state)[0]


def helpful(problem: Problem, state: State) -> frozenset[Action]:
    """The helpful actions of ``state`` (`task.symbolic.relaxed.helpful`): the moves of its
    relaxed plan that apply in ``state``, which the greedy fallback search tries first."""
    actions = _task(problem).actions
    return frozenset(actions[j] for j in _relaxed(problem, state)[1])


# ---------------------------------------------------------------------------------- samples

GRIPPER = """(define (domain tiny-gripper)
  (:requirements :strips :typing)
  (:types room ball gripper)
  (:predicates (at-robby ?r - room) (at ?b - ball ?r - room) (free ?g - gripper)
               (carry ?b - ball ?g - gripper))
  (:action move :parameters (?from ?to - room)
    :precondition (at-robby ?from) :effect (and (at-robby ?to) (not (at-robby ?from))))
  (:action pick :parameters (?b - ball ?r - room ?g - gripper)
    :precondition (and (at ?b ?r) (at-robby ?r) (free ?g))
    :effect (and (carry ?b ?g) (not (at ?b ?r)) (not (free ?g))))
  (:action drop :parameters (?b - ball ?r - room ?g - gripper)
    :precondition (and (carry ?b ?g) (at-robby ?r))
    :effect (and (at ?b ?r) (free ?g) (not (carry ?b ?g)))))
"""


def gripper_problem(n_balls: int, seed: int) -> Problem:
    """A tiny typed gripper problem (2 rooms, 2 grippers): balls in random rooms, a random
    goal room per ball, not all already there."""
    rng = random.Random(seed)
    balls = [f"ball{i}" for i in range(1, n_balls + 1)]
    rooms = ["rooma", "roomb"]
    start = [rng.choice(rooms) for _ in balls]
    goal = [rng.choice(rooms) for _ in balls]
    goal[0] = rooms[1 - rooms.index(start[0])]
    init = " ".join(f"(at {b} {r})" for b, r in zip(balls, start, strict=True))
    wanted = " ".join(f"(at {b} {r})" for b, r in zip(balls, goal, strict=True))
    text = (
        f"(define (problem tiny-gripper-{n_balls}-{seed}) (:domain tiny-gripper)\n"
        f"  (:objects rooma roomb - room left right - gripper {' '.join(balls)} - ball)\n"
        f"  (:init (at-robby {rng.choice(rooms)}) (free left) (free right) {init})\n"
        f"  (:goal (and {wanted})))\n"
    )
    return problem_from_text(GRIPPER, text, f"tiny-gripper-{n_balls}-{seed}")


def samples(seed: int) -> Iterator[Problem]:
    """Blocksworld of 3 to 5 blocks (the embedded untyped 4-op domain) and typed tiny gripper
    problems of 2 and 3 balls."""
    from task import data
    from task.domains import blocksworld
    from task.symbolic.generate import random_problem

    for n_blocks in (3, 4, 5):
        text = blocksworld.to_pddl(random_problem(n_blocks, seed))
        yield problem_from_text(data.read_text(data.DOMAIN_FILE), text, f"bw-{n_blocks}-{seed}")
    for n_balls in (2, 3):
        yield gripper_problem(n_balls, seed)


class Strips(DomainBase):
    """The generic STRIPS lift the shared planner drives (see task.domains.base.Domain)."""

    name = NAME
    size_name = "objects"
    goal_losses = strips_soft.GOAL_LOSSES
    distributions = False  # atoms are independent probabilities in [0, 1]
    encode = staticmethod(strips_soft.encode)
    step = staticmethod(strips_soft.step)
    consistency = staticmethod(strips_soft.consistency)
    cycle_loss = staticmethod(zero_cycle_loss)  # one row: no relation to cycle
    goal_loss = staticmethod(strips_soft.goal_loss)
    decode = staticmethod(decode)
    initial_state = staticmethod(initial_state)
    check_move = staticmethod(check_move)
    apply_move = staticmethod(apply_move)
    legal_moves = staticmethod(legal_moves)
    is_goal = staticmethod(is_goal)
    lower_bound = staticmethod(lower_bound)
    estimate = staticmethod(estimate)
    has_estimate = True
    helpful = staticmethod(helpful)
    from_pddl = staticmethod(from_pddl)
    to_actions = staticmethod(to_actions)
    to_atoms = staticmethod(to_atoms)
    to_pddl = staticmethod(to_pddl)
    pddl_domain_text = staticmethod(pddl_domain_text)
    samples = staticmethod(samples)
    # when the windows revisit a state or run out, a complete greedy search on h_FF and the
    # helpful actions takes over (`PlannerConfig.fallback`; `lazy_search.lazy_greedy`); plans
    # leave with their cycles and redundant moves cut (`task.symbolic.shorten`)
    # windows count ground actions, not moves: a 4-op Blocksworld move is two (pick, place), a
    # gripper round trip six, so the lift's windows are longer than the hand-written domains'
    # 3 and 5 (soft only, after 10 windows: miconic task12 h_FF 10 -> 3 left, BENCHMARKS.md)
    planner_defaults = MappingProxyType(
        {
            "horizon": 4,
            "lookahead": 8,
            "fallback": True,
            "fallback_search": "greedy",
            "fallback_nodes": 50_000,
            "shorten": True,
            "window_share": 0.5,  # under a time limit, half of it for the greedy search
        }
    )

    @staticmethod
    def matches(domain: PDDLDomain) -> bool:
        """Any domain: the registry tries the lift last (unsupported features raise later)."""
        return True

    @staticmethod
    def shape_key(problem: Problem) -> int:
        """The ground action count rounded up to two steps per octave (8, 12, 16, 24, ...):
        problems of one key share a tensor program. On CPU a window costs mostly per-op
        overhead, so few programs beat little padding: Logistics-200 makes 9 programs with
        15% padded action columns (67 with exact sizes, 15 at four steps per octave: 7%)."""
        g = len(_task(problem).actions)
        unit = 1 << max(g.bit_length() - 2, 0)
        return -(-g // unit) * unit

    @staticmethod
    def size(problem: Problem) -> int:
        return len(_task(problem).pddl_problem.objects)


DOMAIN = Strips()
