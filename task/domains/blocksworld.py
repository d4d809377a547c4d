"""The blocksworld domain: crisp moves, soft gates, moves <-> 4-op actions, the domain object.

Relational view: each block rests on one support (another block or the table); the move
``move(x -> y)`` takes a clear block ``x`` onto the table or onto another clear block ``y``.
PDDL view: the 4-operator PlanBench domain ``blocksworld-4ops`` (pick-up, put-down, stack,
unstack), where each move is two actions: ``(unstack x s)`` or ``(pick-up x)``, then
``(stack x y)`` or ``(put-down x)``. A crisp state is the support of every entity, in
``problem.entities`` order. All functions are pure. Reading and writing problem PDDL is
`task.domains.blocksworld_pddl` (re-exported here); full goal scenes and the most likely state
of a perceived soft state are `tamp.camera.states` (the camera's side).
"""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import Tensor

from task.domains import blocksworld_pddl as _pddl
from task.domains.base import SoftBatch, encode_supports, relational_decode, relational_step
from task.errors import ProblemError, one_of
from task.problem import TABLE, Action, Move, Problem
from task.soft import column_free, exclusive_support, goal_cross_entropy, row_normalise
from task.symbolic.search import moves_lower_bound

State = tuple[str, ...]
# the domain's PDDL mapping, re-exported
NAME, PDDL_DOMAIN, OPERATORS = _pddl.NAME, _pddl.PDDL_DOMAIN, _pddl.OPERATORS
from_pddl, to_pddl, support_error = _pddl.from_pddl, _pddl.to_pddl, _pddl.support_error
problem_from_text, problem_from_files = _pddl.problem_from_text, _pddl.problem_from_files

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


def moves_to_actions(
    problem: Problem, moves: Sequence[Move], strict: bool = True
) -> tuple[Action, ...]:
    """The 4-op plan of ``moves``, replayed from init (ProblemError on an illegal move).

    ``strict=False`` translates an illegal move too (picked from where the replay puts it), so
    that a validator can name the first step that fails; the replay then goes on as if it had
    succeeded. Unknown names raise ProblemError either way."""
    state, out = initial_state(problem), []
    for move in moves:
        i = _entity(problem, move.entity)
        source = state[i]
        if strict:
            state = apply_move(problem, state, move)
        else:
            problem.index(move.target)
            state = (*state[:i], move.target, *state[i + 1 :])
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


GOAL_LOSSES = ("towers", "atoms")  # the first is the default


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """The goal term of the objective: ``atoms`` (the paper's CE) or ``towers`` (default).
    -> (B,)."""
    if kind == "atoms":
        return goal_cross_entropy(F, batch.goal)
    if kind in ("towers", "default"):
        return tower_cross_entropy(F, batch)
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")


def legal_moves(problem: Problem, state: State) -> list[Move]:
    """Every legal move in ``state``, entities in order, targets in order."""
    moves = [Move(x, y) for x in problem.entities for y in problem.targets if y != x]
    return [m for m in moves if check_move(problem, state, m) is None]


def to_atoms(problem: Problem, state: State) -> frozenset[tuple[str, ...]]:
    """The 4-op PDDL atoms of ``state`` (hand empty between moves)."""
    atoms = {("handempty",)}
    for x, s in zip(problem.entities, state, strict=True):
        atoms.add(("ontable", x) if s == TABLE else ("on", x, s))
        if is_clear(problem, state, x):
            atoms.add(("clear", x))
    return frozenset(atoms)


def samples(seed: int):
    """Random problems of 3 to 6 blocks (`task.symbolic.generate.random_problem`)."""
    from task.symbolic.generate import random_problem

    for n_blocks in (3, 4, 5, 6):
        yield random_problem(n_blocks, seed)


class Blocksworld:
    """The blocksworld domain object the shared planner drives (see task.domains.base.Domain)."""

    name = NAME
    size_name = "blocks"
    goal_losses = GOAL_LOSSES
    distributions = True
    encode = staticmethod(encode_supports)
    soft_legality = staticmethod(soft_legality)
    step = staticmethod(relational_step(soft_legality))
    decode = staticmethod(relational_decode)
    consistency = staticmethod(consistency)
    cycle_loss = staticmethod(cycle_loss)
    goal_loss = staticmethod(goal_loss)
    initial_state = staticmethod(initial_state)
    check_move = staticmethod(check_move)
    apply_move = staticmethod(apply_move)
    is_goal = staticmethod(is_goal)
    to_actions = staticmethod(moves_to_actions)
    lower_bound = staticmethod(moves_lower_bound)
    legal_moves = staticmethod(legal_moves)
    to_atoms = staticmethod(to_atoms)
    to_pddl = staticmethod(to_pddl)
    from_pddl = staticmethod(from_pddl)
    samples = staticmethod(samples)
    matches = staticmethod(_pddl.matches)
    pddl_domain_text = staticmethod(_pddl.pddl_domain_text)

    @staticmethod
    def shape_key(problem: Problem) -> int:
        return problem.n

    @staticmethod
    def size(problem: Problem) -> int:
        return problem.n


DOMAIN = Blocksworld()
