"""The blocksworld domain: its PDDL mapping and its crisp moves.

Relational view: each block rests on one support (another block or the table); the move
``move(x -> y)`` takes a clear block ``x`` onto the table or onto another clear block ``y``.
PDDL view: the 4-operator PlanBench domain ``blocksworld-4ops`` (pick-up, put-down, stack,
unstack), where each move is two actions: ``(unstack x s)`` or ``(pick-up x)``, then
``(stack x y)`` or ``(put-down x)``. A crisp state is the support of every entity, in
``problem.entities`` order. All functions are pure.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

import torch
from pddl.core import Domain
from pddl.core import Problem as PDDLProblem
from torch import Tensor

from task.domains.base import SoftBatch, encode_supports
from task.errors import PDDLError, ProblemError, one_of
from task.problem import TABLE, Action, Move, Problem
from task.soft import column_free, exclusive_support, goal_cross_entropy, row_normalise
from task.symbolic import pddl_io, strips
from task.symbolic.search import moves_lower_bound

NAME = "blocksworld"
PDDL_DOMAIN = "blocksworld-4ops"
OPERATORS = ("pick-up", "put-down", "stack", "unstack")
State = tuple[str, ...]

_ARITY = {"on": 2, "ontable": 1, "clear": 1, "holding": 1, "handempty": 0}

# ---------------------------------------------------------------------------- PDDL in and out


def _natural(name: str) -> tuple:
    return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", name))


def _support_error(pairs: Sequence[tuple[str, str]]) -> str | None:
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
    reason = _support_error(pairs)
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
    reason = _support_error(goal)
    if reason is not None:
        raise PDDLError(f"unsolvable goal: {reason}")
    return goal


def from_pddl(domain: Domain, problem: PDDLProblem, order: Sequence[str] | None = None) -> Problem:
    """The relational `Problem` of a parsed blocksworld problem.

    ``order`` gives the entity order (the file order, see `pddl_io.object_order`); without it
    the objects are sorted naturally (a < b < ... , b2 < b10), since `pddl` keeps only a set.
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
    parsed = pddl_io.parse_problem(text, source, domain)
    try:
        return from_pddl(domain, parsed, pddl_io.object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None


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
        lines.append(f"(ontable {x})" if s == TABLE else f"(on {x} {s})")
    lines += [f"(clear {x})" for x in problem.entities if x not in problem.init]
    goal = [f"(ontable {x})" if y == TABLE else f"(on {x} {y})" for x, y in problem.goal]
    lines += [")", "(:goal"]
    lines += ["(and", *goal[:-1], goal[-1] + ")"] if goal else ["(and)"]
    lines += [")", ")"]
    return "\n".join(lines) + "\n"


# -------------------------------------------------------------------------------------- crisp


def _entity(problem: Problem, x: str) -> int:
    if x not in problem.entities:
        raise ProblemError(f"unknown block {one_of(x, problem.entities)}")
    return problem.entities.index(x)


def initial_state(problem: Problem) -> State:
    """The support of every entity at the start."""
    return tuple(problem.init)


def _above(problem: Problem, state: State, x: str) -> str | None:
    return next((e for e, s in zip(problem.entities, state, strict=True) if s == x), None)


def is_clear(problem: Problem, state: State, x: str) -> bool:
    """Whether nothing rests on ``x`` (a fixed target such as the table is always clear)."""
    problem.index(x)
    return x in problem.fixed or x not in state


def check_move(problem: Problem, state: State, move: Move) -> str | None:
    """None if ``move`` is legal in ``state``, else a one-line reason (ProblemError: unknown)."""
    i = _entity(problem, move.entity)
    problem.index(move.target)
    x, y = move.entity, move.target
    if x == y:
        return f"{x} cannot be moved onto itself"
    if state[i] == y:
        return f"{x} is already on {y}"
    for z, label in ((x, x), (y, f"target {y}")):
        if not is_clear(problem, state, z):
            return f"{label} is not clear ({_above(problem, state, z)} is on it)"
    return None


def apply_move(problem: Problem, state: State, move: Move) -> State:
    """The state after ``move``; raises ProblemError if it is illegal."""
    reason = check_move(problem, state, move)
    if reason is not None:
        raise ProblemError(f"illegal {move}: {reason}")
    i = _entity(problem, move.entity)
    return (*state[:i], move.target, *state[i + 1 :])


def unsatisfied_goals(problem: Problem, state: State) -> tuple[tuple[str, str], ...]:
    """The goal atoms ``(x, support)`` that do not hold in ``state``."""
    return tuple((x, y) for x, y in problem.goal if state[_entity(problem, x)] != y)


def is_goal(problem: Problem, state: State) -> bool:
    """Whether every goal atom holds in ``state``."""
    return not unsatisfied_goals(problem, state)


# ---------------------------------------------------------------------------- moves <-> actions


def moves_to_actions(problem: Problem, moves: Sequence[Move]) -> tuple[Action, ...]:
    """The 4-op plan of ``moves``, replayed from init (ProblemError on an illegal move)."""
    state, out = initial_state(problem), []
    for move in moves:
        source = state[_entity(problem, move.entity)]
        state = apply_move(problem, state, move)
        x, y = move.entity, move.target
        out.append(Action("pick-up", (x,)) if source == TABLE else Action("unstack", (x, source)))
        out.append(Action("put-down", (x,)) if y == TABLE else Action("stack", (x, y)))
    return tuple(out)


def actions_to_moves(problem: Problem, actions: Sequence[Action]) -> tuple[Move, ...]:
    """Pair a 4-op plan into moves; ProblemError unless it alternates pick and put."""
    picks, puts = {"pick-up": 1, "unstack": 2}, {"put-down": 1, "stack": 2}
    moves: list[Move] = []
    held = ""
    for k, action in enumerate(actions, start=1):
        name, args = action.name.lower(), tuple(a.lower() for a in action.args)
        kinds = puts if held else picks
        if kinds.get(name) != len(args):
            wanted = "(put-down x) or (stack x y)" if held else "(pick-up x) or (unstack x y)"
            raise ProblemError(f"action {k} {action}: expected {wanted} (pick and put alternate)")
        _entity(problem, args[0])
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


# ------------------------------------------------------------------------------------ soft


def soft_legality(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. gate factors: legal(x, y) = c(x) * cbar(y) * e(x, y) * (1 - F[x, y]).

    c is the soft clear (product t-norm), cbar(table) = 1, e masks self-support and padding,
    and (1 - F[x, y]) removes the null move onto the current support. (B, N, Y) -> (B, N, Y).
    """
    n = batch.n
    c = column_free(F, n)  # (B, N)
    cbar = torch.cat([c, torch.ones_like(F[:, 0, n:])], dim=-1)  # (B, Y)
    e = batch.action_mask[..., :-1].to(F.dtype)  # (B, N, Y)
    return c.unsqueeze(-1) * cbar.unsqueeze(-2) * e * (1.0 - F)


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. T_P: target exclusivity on block columns, then row normalisation. (B, N, Y)."""
    return row_normalise(exclusive_support(F, batch.n))


def cycle_loss(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. two-cycle: sum_{x < y} F[x, y] F[y, x] over block pairs. (B, N, Y) -> (B,)."""
    blocks = F[..., : batch.n]  # (B, N, N)
    return 0.5 * (blocks * blocks.transpose(-1, -2)).sum((-1, -2))


def log_well_placed(F: Tensor, batch: SoftBatch) -> Tensor:
    """Log of the soft "x will never have to move again", log w(x): (B, N, Y) -> (B, N).

    Goal blocks: w(x) = F[x, g(x)] * wbar(g(x)); blocks the goal leaves free:
    w(x) = sum_y F[x, y] wbar(y); wbar(table) = 1. Computed in log space (products along a
    tower of N blocks underflow otherwise). A problem of n blocks gets exactly n sweeps of the
    recursion (its fixed point on crisp towers), whatever the padding.
    """
    n = batch.n
    sweeps = batch.entity_mask.sum(-1, keepdim=True)  # (B, 1) real blocks per row
    has_goal = batch.goal.sum(-1) > 0  # (B, N)
    log_f = torch.log(F.clamp_min(torch.finfo(F.dtype).tiny))  # (B, N, Y)
    log_on_goal = (log_f * batch.goal).sum(-1)  # log F[x, g(x)], (B, N)
    lw = torch.zeros_like(log_on_goal)
    zeros = torch.zeros_like(F[:, 0, n:])  # (B, K): log wbar(table) = 0
    for k in range(n):
        lwbar = torch.cat([lw, zeros], dim=-1).unsqueeze(-2)  # (B, 1, Y)
        goal_term = log_on_goal + (batch.goal * lwbar).sum(-1)  # (B, N)
        free_term = torch.logsumexp(log_f + lwbar, dim=-1)  # (B, N)
        lw = torch.where(k < sweeps, torch.where(has_goal, goal_term, free_term), lw)
    return lw


def tower_cross_entropy(F: Tensor, batch: SoftBatch) -> Tensor:
    """Goal cross-entropy on well-placed goal blocks: -sum_{x in goal} log w(x). -> (B,)."""
    has_goal = batch.goal.sum(-1)  # (B, N)
    return -(has_goal * log_well_placed(F, batch)).sum(-1)


GOAL_LOSSES = ("atoms", "towers")


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """The goal term of the objective: ``atoms`` (the paper's CE) or ``towers``. -> (B,)."""
    if kind == "atoms":
        return goal_cross_entropy(F, batch.goal)
    if kind == "towers":
        return tower_cross_entropy(F, batch)
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")


def complete_goal(problem: Problem) -> State:
    """A full state that satisfies the (partial) goal: blocks the goal does not mention keep
    their initial support when it stays free and makes no cycle, else go on the table."""
    support = dict(problem.goal)
    above = {y: x for x, y in support.items() if y != TABLE}
    for x, start in zip(problem.entities, problem.init, strict=True):
        if x in support:
            continue
        y = start
        if y != TABLE:
            chain = y
            while chain in support and chain != x:
                chain = support[chain]
            if y in above or chain == x:
                y = TABLE
        support[x] = y
        if y != TABLE:
            above[y] = x
    reason = _support_error(list(support.items()))
    if reason is not None:
        raise ProblemError(f"cannot complete the goal of {problem.name}: {reason}")
    return tuple(support[x] for x in problem.entities)


# ----------------------------------------------------------------------- soft -> crisp states

ENUMERATE_UP_TO = 7  # blocks; 37,633 states at 7, 394,353 at 8


@functools.cache
def all_states(n: int) -> Tensor:
    """Every blocksworld state of ``n`` blocks as support columns (S, n) (table = column n).

    Built by inserting block k into any position of any tower, or as a new tower: each set of
    ordered towers arises exactly once (13, 73, 501, 4051 states for 3..6 blocks).
    """
    configs: list[list[list[int]]] = [[]]
    for k in range(n):
        grown = []
        for towers in configs:
            grown.append([*towers, [k]])
            for t, tower in enumerate(towers):
                for j in range(len(tower) + 1):
                    grown.append([*towers[:t], [*tower[:j], k, *tower[j:]], *towers[t + 1 :]])
        configs = grown
    out = torch.empty(len(configs), n, dtype=torch.long)
    for i, towers in enumerate(configs):
        for tower in towers:
            for below, x in zip([n, *tower], tower, strict=False):
                out[i, x] = below
    return out


def most_likely_state(problem: Problem, F: Tensor) -> tuple[str, ...]:
    """The crisp state that maximises sum_x log F[x, support(x)] among valid blocksworld states
    (no two blocks on one, no cycles): exact by enumeration up to `ENUMERATE_UP_TO` blocks,
    the row-wise most likely supports above that (ProblemError if they are not a state).

    F: (N, Y) soft supports with N >= problem.n rows and the table at column N.
    """
    n, rows = problem.n, F.shape[0]
    if F.ndim != 2 or rows < n or F.shape[1] != rows + len(problem.fixed):
        raise ProblemError(f"soft state of shape {tuple(F.shape)} does not fit {n} blocks")
    logf = torch.log(F.detach().double().clamp_min(1e-300))  # (N, Y)
    blocks = torch.cat([logf[:n, :n], logf[:n, rows:]], dim=1)  # (n, n+1), table last
    names = [*problem.entities, TABLE]
    if n <= ENUMERATE_UP_TO:
        states = all_states(n)  # (S, n)
        score = blocks.gather(1, states.T).sum(0)  # (S,)
        return tuple(names[c] for c in states[int(score.argmax())].tolist())
    state = tuple(names[c] for c in blocks.argmax(1).tolist())
    reason = _support_error(list(zip(problem.entities, state, strict=True)))
    if reason is not None:
        raise ProblemError(f"the most likely supports are not a state: {reason}")
    return state


class Blocksworld:
    """The blocksworld domain object the shared planner drives (see task.domains.base.Domain)."""

    name = NAME
    encode = staticmethod(encode_supports)
    soft_legality = staticmethod(soft_legality)
    consistency = staticmethod(consistency)
    cycle_loss = staticmethod(cycle_loss)
    goal_loss = staticmethod(goal_loss)
    initial_state = staticmethod(initial_state)
    check_move = staticmethod(check_move)
    apply_move = staticmethod(apply_move)
    is_goal = staticmethod(is_goal)
    to_actions = staticmethod(moves_to_actions)
    lower_bound = staticmethod(moves_lower_bound)


DOMAIN = Blocksworld()
