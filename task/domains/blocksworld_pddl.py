"""Blocksworld problems in and out of PDDL: the 4-operator PlanBench domain ``blocksworld-4ops``.

`from_pddl` reads a parsed problem into a relational `Problem` (each block's support), checking
that the init is a hand-empty blocksworld state and that the goal is a set of support atoms that
can hold at once (`support_error` names why not); `to_pddl` writes a problem back as
PlanBench-style text; `write_instances` writes seeded random problems as instance files. The
moves <-> actions mapping lives with the domain (`blocksworld`).
"""

from __future__ import annotations

import random
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.deadline import NO_DEADLINE, Deadline
from task.errors import PDDLError, ProblemError, one_of
from task.problem import TABLE, Action, Move, Problem
from task.symbolic import pddl_io, strips
from task.symbolic.generate import random_problem
from task.symbolic.signature import signature

NAME = "blocksworld"
PDDL_DOMAIN = "blocksworld-4ops"
OPERATORS = ("pick-up", "put-down", "stack", "unstack")
_ARITY = {"on": 2, "ontable": 1, "clear": 1, "holding": 1, "handempty": 0}


def _natural(name: str) -> tuple:
    return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", name))


def support_error(pairs: Sequence[tuple[str, str]]) -> str | None:
    """Why the ``(block, support)`` atoms cannot all hold at once, or None if they can."""
    below: dict[str, str] = {}
    above: dict[str, str] = {}
    for x, y in pairs:
        if x == y:
            return f"(on {x} {x}) puts {x} on itself"
        if below.get(x, y) != y:
            return f"{x} has two supports: {below[x]}, {y}"
        if y != TABLE and above.get(y, x) != x:
            return f"{above[y]} and {x} are both on {y}"
        below[x] = y
        if y != TABLE:
            above[y] = x
    for start in below:
        chain, x = [start], below[start]
        while x in below and x not in chain:
            chain.append(x)
            x = below[x]
        if x == start:
            return "cycle " + " on ".join([*chain, start])
    return None


def _atoms(atoms: Iterable[strips.Atom], objects: Sequence[str], where: str) -> list[strips.Atom]:
    """Sorted blocksworld atoms; PDDLError for a foreign predicate or an unknown object."""
    ordered = sorted(atoms)
    for atom in ordered:
        if _ARITY.get(atom[0]) != len(atom) - 1:
            raise PDDLError(f"{where} atom {strips.atom_str(atom)} is not a blocksworld atom")
        for arg in (a for a in atom[1:] if a not in objects):
            text = strips.atom_str(atom)
            raise PDDLError(f"{where} atom {text} names unknown object {one_of(arg, objects)}")
    return ordered


def _init(problem: PDDLProblem, objects: Sequence[str]) -> tuple[str, ...]:
    atoms = _atoms(strips.initial_state(problem), objects, "init")
    held = [strips.atom_str(a) for a in atoms if a[0] == "holding"]
    if held or ("handempty",) not in atoms:
        what = f"has {held[0]}" if held else "lacks (handempty)"
        raise PDDLError(f"init {what}: the hand must be empty at the start")
    pairs = [(a[1], a[2] if a[0] == "on" else TABLE) for a in atoms if a[0] in ("on", "ontable")]
    reason = support_error(pairs)
    if reason is not None:
        raise PDDLError(f"init: {reason}")
    support, clear = dict(pairs), {a[1] for a in atoms if a[0] == "clear"}
    for x in objects:
        on_x = [y for y, s in pairs if s == x]
        if x not in support:
            raise PDDLError(f"init: block {x} has no support (needs (ontable {x}) or (on {x} ...))")
        if x in clear and on_x:
            raise PDDLError(f"init: (clear {x}) is inconsistent with (on {on_x[0]} {x})")
        if x not in clear and not on_x:
            raise PDDLError(f"init: nothing is on {x} but (clear {x}) is missing")
    return tuple(support[x] for x in objects)


def _goal(problem: PDDLProblem, objects: Sequence[str]) -> tuple[tuple[str, str], ...]:
    atoms = strips.goal_atoms(problem)
    _atoms(atoms, objects, "goal")
    other = [strips.atom_str(a) for a in atoms if a[0] not in ("on", "ontable", "handempty")]
    if other:
        raise PDDLError(f"{other[0]} in the goal cannot be expressed as a support relation")
    goal = tuple((a[1], a[2] if a[0] == "on" else TABLE) for a in atoms if a[0] != "handempty")
    reason = support_error(goal)
    if reason is not None:
        raise PDDLError(f"unsolvable goal: {reason}")
    return goal


def from_pddl(
    domain: Domain,
    problem: PDDLProblem,
    order: Sequence[str] | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> Problem:
    """The relational `Problem` of a parsed blocksworld problem.

    ``order`` gives the entity order (the file order, see `pddl_io.object_order`); without it
    the objects are sorted naturally (a < b < ... , b2 < b10), since `pddl` keeps only a set.
    ``deadline`` is not looked at: the reading is linear in the problem (`Domain.from_pddl`).
    """
    actions = {str(a.name).lower() for a in domain.actions}
    if actions != set(OPERATORS):
        raise PDDLError(
            f"domain {domain.name} is not the 4-operator blocksworld (needs {', '.join(OPERATORS)})"
        )
    names = {str(o.name).lower() for o in problem.objects}
    objects = tuple(order) if order is not None else tuple(sorted(names, key=_natural))
    if set(objects) != names or len(objects) != len(names) or TABLE in names:
        raise PDDLError(
            f"objects {sorted(names)} (in order {objects}) must be distinct, not {TABLE}"
        )
    init, goal = _init(problem, objects), _goal(problem, objects)
    return Problem(str(problem.name), NAME, objects, init, goal)


def problem_from_text(domain: Domain, text: str, source: str = "<problem>") -> Problem:
    """Parse problem PDDL text (keeping the file's object order) into a `Problem`."""
    return pddl_io.problem_with(from_pddl, domain, text, source)


def problem_from_files(domain_path: str | Path, problem_path: str | Path) -> Problem:
    """Load a domain and a problem file into a `Problem`; errors name the offending file."""
    domain = pddl_io.load_domain(domain_path)
    return problem_from_text(domain, pddl_io.read_text(problem_path), str(problem_path))


def to_pddl(problem: Problem) -> str:
    """PlanBench-style problem PDDL text (objects, init with clear atoms, ``and`` goal)."""
    objects = "".join(f"{x} " for x in problem.entities)
    lines = [f"(define (problem {problem.name})", f"(:domain {PDDL_DOMAIN})"]
    lines += [f"(:objects {objects})", "(:init", "(handempty)"]
    for x, s in zip(problem.entities, problem.init, strict=True):
        lines.append(f"(ontable {x})" if s in problem.fixed else f"(on {x} {s})")
    lines += [f"(clear {x})" for x in problem.entities if x not in problem.init]
    goal = [f"(ontable {x})" if y == TABLE else f"(on {x} {y})" for x, y in problem.goal]
    lines += [")", "(:goal"]
    lines += ["(and", *goal[:-1], goal[-1] + ")"] if goal else ["(and)"]
    lines += [")", ")"]
    return "\n".join(lines) + "\n"


def write_instances(out_dir: str | Path, n_blocks: int, n: int, seed: int) -> tuple[Path, ...]:
    """Write ``instance-1.pddl .. instance-n.pddl`` (PlanBench format) of seeded random problems
    (`task.symbolic.generate.random_problem`) and return their paths.

    Instance ``i`` uses the ``i``-th seed drawn from ``random.Random(seed)``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    seeds = random.Random(seed)
    paths = []
    for i in range(1, n + 1):
        problem = random_problem(n_blocks, seeds.randrange(2**31))
        path = out / f"instance-{i}.pddl"
        path.write_text(to_pddl(problem), encoding="utf-8")
        paths.append(path)
    return tuple(paths)


def pddl_domain_text() -> str:
    """The embedded 4-op domain's text (`task.data`)."""
    from task import data  # task.data parses with task.symbolic; imported when asked

    return data.read_text(data.DOMAIN_FILE)


def matches(domain: Domain) -> bool:
    """Whether a parsed PDDL domain has the 4-op actions and predicates with their arities."""
    from task import data

    return signature(domain) == signature(data.domain())


def slotted(problem: Problem) -> bool:
    """Whether the table is K named slots of capacity one (``problem.fixed``, the paper's K
    base slots) instead of one unlimited table; a goal ``(x, "table")`` then means x on any
    slot, and a move names the slot it puts a block on."""
    return problem.fixed != (TABLE,)


def actions_to_moves(problem: Problem, actions: Sequence[Action]) -> tuple[Move, ...]:
    """Pair a 4-op plan into moves; ProblemError unless it alternates pick and put."""
    if slotted(problem):
        raise ProblemError(
            f"{problem.name} has table slots {problem.fixed}: give moves, not actions"
        )
    picks, puts = {"pick-up": 1, "unstack": 2}, {"put-down": 1, "stack": 2}
    moves: list[Move] = []
    held = ""
    for k, action in enumerate(actions, start=1):
        name, args = action.name.lower(), tuple(a.lower() for a in action.args)
        kinds = puts if held else picks
        if kinds.get(name) != len(args):
            wanted = "(put-down x) or (stack x y)" if held else "(pick-up x) or (unstack x y)"
            raise ProblemError(f"action {k} {action}: expected {wanted} (pick and put alternate)")
        if args[0] not in problem.entities:
            raise ProblemError(f"unknown block {one_of(args[0], problem.entities)}")
        if not held:
            held = args[0]
            continue
        if args[0] != held:
            raise ProblemError(f"action {k} {action}: the hand holds {held}, not {args[0]}")
        target = args[1] if name == "stack" else TABLE
        problem.index(target)
        moves.append(Move(held, target))
        held = ""
    if held:
        raise ProblemError(f"plan ends holding {held} (after {actions[-1]})")
    return tuple(moves)


def to_atoms(problem: Problem, state: Sequence[str]) -> frozenset[tuple[str, ...]]:
    """The 4-op PDDL atoms of ``state`` (hand empty between moves)."""
    atoms = {("handempty",)}
    for x, s in zip(problem.entities, state, strict=True):
        atoms.add(("ontable", x) if s in problem.fixed else ("on", x, s))
        if x not in state:
            atoms.add(("clear", x))
    return frozenset(atoms)
