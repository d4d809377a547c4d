"""Whether a PDDL problem provably has no plan: the `Proof` value and `prove_unsolvable`.

The proofs, cheapest first, each sound (``unsolvable`` only when no plan exists):

1. relaxed reachability: a goal atom that the delete relaxation never reaches
   (`task.symbolic.ground.reachable`), e.g. a package bound for a city no vehicle reaches, a
   box in a corner that is not its goal;
2. h^2 (`mutex`): a goal atom no action can add in a reachable state, or two goal atoms that
   never hold together (a block on itself, on two blocks, two blocks on one);
3. an acyclicity invariant proved from h^2 (`mutex.acyclic`): goal atoms that form a cycle
   of a relation every reachable state keeps acyclic (a Blocksworld goal tower that loops);
4. on request, exhaustive breadth-first search (`exhaust`): every reachable state, when there
   are at most ``max_states`` of them and the time limit allows.

Otherwise the result says what was tried and why it proves nothing (too many states, out of
time): the problem may still be solvable. These work on the problem's PDDL, whatever domain
rules plan it; a problem beyond the STRIPS fragment that `ground` reads proves nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.deadline import NO_DEADLINE, Deadline, TimeLimitReached
from task.errors import TampError
from task.symbolic import ground, strips
from task.symbolic.proofs import exhaust, mutex
from task.symbolic.strips_task import StripsTask

METHODS = ("relaxed", "h2", "invariant", "exhaustive")


@dataclass(frozen=True)
class Proof:
    """Whether the problem is proved unsolvable, why (one line naming the atoms) and by
    which of `METHODS` ("" when nothing was proved: ``reason`` says what was tried)."""

    unsolvable: bool
    reason: str
    method: str = ""


def prove_unsolvable(
    domain: Domain,
    problem: PDDLProblem,
    exhaustive: bool = False,
    max_states: int = 100_000,
    time_limit_s: float | None = 10.0,
    max_atoms: int = 2_000,
    deadline: Deadline = NO_DEADLINE,
) -> Proof:
    """Try the proofs of the module docstring on a parsed PDDL problem.

    ``exhaustive``: also search every reachable state (at most ``max_states``); h^2 runs on
    tasks of at most ``max_atoms`` fluent atoms; ``time_limit_s`` bounds h^2 and the search
    (None: no limit). ``deadline``: the command's (`task.deadline`), which bounds every step,
    grounding included; one that passes proves nothing ("time limit (N s) reached while ...").
    """
    ends = deadline.within(time_limit_s)
    try:
        grounding = ground.reachable(domain, problem, deadline)
        goal = strips.goal_atoms(problem)
    except TampError as exc:
        return Proof(False, f"no proof beyond STRIPS ({exc})")
    except TimeLimitReached as exc:
        return Proof(False, f"not proved unsolvable; {exc}")
    reached = set(grounding.atoms)
    missing = [a for a in goal if a not in reached]
    if missing:
        return Proof(
            True,
            f"goal {strips.atom_str(missing[0])} is unreachable, even ignoring delete effects",
            "relaxed",
        )
    task = StripsTask.build(grounding.actions, goal, domain, problem)
    tried = ["relaxed reachability"]
    if len(task.atoms) > max_atoms:
        tried.append(f"h^2 skipped ({len(task.atoms)} atoms > {max_atoms})")
    elif (pairs := mutex.h2(task, ends)) is None:
        tried.append("h^2 ran out of time")
    else:
        tried.append("h^2")
        if why := mutex.goal_conflict(task, pairs):
            return Proof(True, why, "h2")
        if why := mutex.goal_cycle(task, pairs, goal):
            return Proof(True, why, "invariant")
    if exhaustive:
        found = exhaust.exhaust(task, max_states, ends)
        if found.outcome is exhaust.Outcome.UNSOLVABLE:
            return Proof(
                True,
                f"none of the {found.states} reachable states satisfies the goal "
                "(exhaustive search)",
                "exhaustive",
            )
        tried.append(_searched(found, max_states))
    return Proof(False, "not proved unsolvable; tried " + ", ".join(tried))


def _searched(found: exhaust.Exhausted, max_states: int) -> str:
    if found.outcome is exhaust.Outcome.SOLVABLE:
        return f"exhaustive search found a plan of {found.length} actions (solvable)"
    if found.outcome is exhaust.Outcome.CAP:
        return f"exhaustive search stopped at {max_states} states"
    return f"exhaustive search ran out of time after {found.states} states"
