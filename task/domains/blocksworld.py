"""The blocksworld domain: crisp moves, soft gates, moves <-> 4-op actions, the domain object.

Relational view: each block rests on one support (another block or the table); the move
``move(x -> y)`` takes a clear block ``x`` onto the table or onto another clear block ``y``.
PDDL view: the 4-operator PlanBench domain ``blocksworld-4ops`` (pick-up, put-down, stack,
unstack), where each move is two actions: ``(unstack x s)`` or ``(pick-up x)``, then
``(stack x y)`` or ``(put-down x)``. A crisp state is the support of every entity, in
``problem.entities`` order. The table is one unlimited target, or K slots of capacity one
(`with_slots`). Problem PDDL is `task.domains.blocksworld_pddl` (re-exported here).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from types import MappingProxyType

import torch
from torch import Tensor

from task.domains import blocksworld_pddl as _pddl
from task.domains.base import (
    STAY_PRIOR,
    DomainBase,
    SoftBatch,
    encode_supports,
    relational_decode,
    relational_step,
)
from task.domains.match.renaming import user_actions, user_atoms
from task.errors import ProblemError, one_of
from task.problem import TABLE, Action, Move, Problem
from task.soft import (
    column_free,
    exclusive_columns,
    exclusive_support,
    goal_cross_entropy,
    log_any,
    log_chain,
    row_normalise,
)
from task.symbolic.generate import random_problem
from task.symbolic.search import moves_lower_bound

State = tuple[str, ...]
# the domain's PDDL mapping, re-exported
NAME, PDDL_DOMAIN, OPERATORS = _pddl.NAME, _pddl.PDDL_DOMAIN, _pddl.OPERATORS
from_pddl, to_pddl, support_error = _pddl.from_pddl, _pddl.to_pddl, _pddl.support_error
actions_to_moves, to_atoms, slotted = _pddl.actions_to_moves, _pddl.to_atoms, _pddl.slotted
problem_from_text, problem_from_files = _pddl.problem_from_text, _pddl.problem_from_files

# -------------------------------------------------------------------------------------- crisp


def _on(problem: Problem, support: str, y: str) -> bool:  # support satisfies goal support y
    return support == y or (y == TABLE and support in problem.fixed)


def _entity(problem: Problem, x: str) -> int:
    if x not in problem.entities:
        raise ProblemError(f"unknown block {one_of(x, problem.entities)}")
    return problem.entities.index(x)


def initial_state(problem: Problem) -> State:  # the support of every entity at the start
    return tuple(problem.init)


def _above(problem: Problem, state: State, x: str) -> str | None:
    return next((e for e, s in zip(problem.entities, state, strict=True) if s == x), None)


def is_clear(problem: Problem, state: State, x: str) -> bool:
    """Whether nothing rests on ``x`` (the unlimited table is always clear, a slot if empty)."""
    problem.index(x)
    return x == TABLE or x not in state


def check_move(problem: Problem, state: State, move: Move) -> str | None:
    """None if ``move`` is legal in ``state``, else a one-line reason (ProblemError: unknown)."""
    i = _entity(problem, move.entity)
    problem.index(move.target)
    x, y = move.entity, move.target
    if x == y:
        return f"{x} cannot be moved onto itself"
    if state[i] == y or (
        slotted(problem) and not hops(problem) and {state[i], y} <= set(problem.fixed)
    ):
        return f"{x} is already on {'the table' if state[i] != y else y}"
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
    return tuple((x, y) for x, y in problem.goal if not _on(problem, state[_entity(problem, x)], y))


def is_goal(problem: Problem, state: State) -> bool:
    """Whether every goal atom holds in ``state``."""
    return not unsatisfied_goals(problem, state)


def in_position(problem: Problem, state: State) -> frozenset[str]:
    """The blocks that never have to move again (Slaney & Thiebaux's "in position", partial
    goals included): a goal block on its goal support, that support in position or the table;
    a block the goal leaves free on the table, or on a block in position that no goal block
    must stand on. (Supports form no cycle in a state, so the recursion ends.)"""
    goal = dict(problem.goal)
    wanted = {y for y in goal.values() if y != TABLE}
    on = dict(zip(problem.entities, state, strict=True))
    known: dict[str, bool] = {}

    def placed(x: str) -> bool:
        if x not in known:
            below = on[x]
            if x in goal:
                known[x] = _on(problem, below, goal[x]) and (below not in on or placed(below))
            else:
                known[x] = below not in on or (below not in wanted and placed(below))
        return known[x]

    return frozenset(x for x in problem.entities if placed(x))


def constructive_moves(problem: Problem, state: State) -> list[Move]:
    """The legal moves that put a clear block not in position into position (`in_position`):
    onto its goal block when that block is in position and clear, onto the table when the
    goal wants it there or leaves it free. Gupta & Nau's result, which Slaney & Thiebaux's
    GN1 builds on: where such a move exists, some shortest plan starts with it, so taking it
    without a window loses no plan length. Only on the unlimited table (a slotted problem's
    table is a resource: none are returned there)."""
    if slotted(problem):
        return []
    placed = in_position(problem, state)
    goal = dict(problem.goal)
    covered = set(state)
    out = []
    for x in problem.entities:
        if x in covered or x in placed:
            continue
        y = goal.get(x, TABLE)
        if y == TABLE or (y in placed and y not in covered):
            out.append(Move(x, y))
    return [m for m in out if check_move(problem, state, m) is None]


def safe_moves(problem: Problem, state: State) -> tuple[Move, ...]:
    """Constructive moves taken one after another from ``state`` until none is left (each
    may make the next possible): the moves the planner takes without a window
    (`PlannerConfig.safe_from`)."""
    out = []
    while moves := constructive_moves(problem, state):
        out.append(moves[0])
        state = apply_move(problem, state, moves[0])
    return tuple(out)


def unfinished(
    problem: Problem, state: State, depth: int | None = None
) -> tuple[Problem, tuple[int, ...]] | None:
    """The part of ``problem`` still to be planned from ``state``. Blocks in position
    (`in_position`) never move again in some shortest plan, so of each tower's in-position
    segment only its top is kept, as a block standing on the table (its goal, if any, the
    table): the rest of the segment can receive nothing more (the block on it is the one the
    goal wants there, or no goal wants it). A top with nothing on it that no goal block still
    has to come onto is dropped too. No kept block rests on a dropped one and no goal atom of
    a kept block names one, so the part is a problem of its own, with the same moves and
    shortest plans as ``problem`` from ``state`` (a window's soft problem shrinks as towers
    are built). The part is marked `GOAL_OR_TABLE`: its windows move a block only onto its
    goal block or the table, which keeps some shortest plan (`_goal_or_table`).

    With ``depth`` (the longest window's moves), only what a window of ``depth`` moves can
    change is kept (`_within_reach`): the part is then exact for every plan of at most
    ``depth`` moves but no longer a problem of its own (its goal is out of reach).

    Returns the part and the indices of its blocks in ``problem.entities`` (all of them when
    nothing is dropped; a part cut at ``depth`` has entities of its own after them), or None
    on a slotted table."""
    if slotted(problem):
        return None
    placed = in_position(problem, state)
    above = {y: x for x, y in zip(problem.entities, state, strict=True) if y != TABLE}
    wanted = {y for _, y in problem.goal if y != TABLE}

    def dropped(x: str) -> bool:
        top = above.get(x)
        return x in placed and (top in placed or (top is None and x not in wanted))

    keep = tuple(i for i, x in enumerate(problem.entities) if not dropped(x))
    goal = dict(problem.goal)
    rooted = {problem.entities[i] for i in keep} & placed  # the kept tops of the segments
    init = tuple(TABLE if problem.entities[i] in rooted else state[i] for i in keep)
    entities = tuple(problem.entities[i] for i in keep)
    atoms = tuple((x, TABLE if x in rooted else goal[x]) for x in entities if x in goal)
    part = replace(problem, entities=entities, init=init, goal=atoms, data=GOAL_OR_TABLE)
    if depth is None:
        return part, keep
    part, near = _within_reach(part, depth)
    return part, tuple(keep[j] for j in near)


PEDESTAL = "_pedestal-{}"  # a `_within_reach` part's own entities (no PDDL name starts so)


def _within_reach(part: Problem, depth: int) -> tuple[Problem, tuple[int, ...]]:
    """``part`` (standing in its ``init``) cut to what ``depth`` moves can change, and the
    indices of the blocks kept in ``part.entities``.

    A block with ``depth`` or more blocks above it can neither move nor receive a block
    within ``depth`` moves (clearing it takes that many). Of each tower the blocks above
    that level are kept as they are; the first one at it, the *root*, is kept with the table
    as its goal, standing on the table where it is in position in ``part`` and otherwise on a
    *pedestal*, an entity of the cut part's own that nothing reaches (the root never leaves
    it within ``depth`` moves). Blocks deeper down are dropped. A kept block whose goal block
    is dropped can reach it in no plan of ``depth`` moves: its goal becomes the pedestal of
    that tower, a goal never met (that tower's root is not in position, as a block in
    position stands on that goal block, and it is not the kept one). A block the goal leaves
    free that stands on a block a root or a dropped block must stand on gets the table as its
    goal (it is in position only there). For every plan of at most ``depth`` moves from
    ``part.init`` that moves each block only onto its goal block or the table (the part's
    moves, `GOAL_OR_TABLE`), the cut part has the same legal moves (but after the last), each
    kept block the same in-position truth and, but for the roots, the same support, and the
    cut's goal holds exactly when ``part``'s does. ``part`` itself when no tower reaches the
    level."""
    support = dict(zip(part.entities, part.init, strict=True))
    covered = set(part.init)
    level: dict[str, int] = {}  # blocks above each block, for the blocks near the top
    for top in (x for x in part.entities if x not in covered):
        x, k = top, 0
        while x != TABLE and k <= depth:
            level[x], x, k = k, support[x], k + 1
    if len(level) == part.n:
        return part, tuple(range(part.n))
    placed = in_position(part, part.init)
    roots = [x for x in part.entities if level.get(x) == depth]
    stands = {r: PEDESTAL.format(i) for i, r in enumerate(r for r in roots if r not in placed)}
    tower: dict[str, str] = {}  # each dropped block's root
    for root in roots:
        x = support[root]
        while x != TABLE:
            tower[x], x = root, support[x]
    goal = dict(part.goal)
    claimed = {goal[z] for z in (*tower, *roots) if z in goal}  # by a block that stays
    near = tuple(j for j, x in enumerate(part.entities) if x in level)
    entities = tuple(part.entities[j] for j in near)
    atoms = []
    for x in entities:
        if level[x] == depth:
            atoms.append((x, TABLE))
        elif goal.get(x) in tower:  # a dropped goal block; its root is not in position
            if tower[goal[x]] in stands:  # (always, for a goal one state can meet)
                atoms.append((x, stands[tower[goal[x]]]))
        elif x in goal:
            atoms.append((x, goal[x]))
        elif support[x] in claimed:
            atoms.append((x, TABLE))
    init = tuple(stands.get(x, TABLE) if level[x] == depth else support[x] for x in entities)
    pedestals = tuple(stands.values())
    cut = replace(
        part,
        entities=entities + pedestals,
        init=init + (TABLE,) * len(pedestals),
        goal=tuple(atoms),
    )
    return cut, near


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
        on_table = source in problem.fixed
        out.append(Action("pick-up", (x,)) if on_table else Action("unstack", (x, source)))
        out.append(Action("put-down", (x,)) if y in problem.fixed else Action("stack", (x, y)))
    return tuple(out)


# ------------------------------------------------------------------------------------ soft


def soft_legality(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. gate factors: legal(x, y) = c(x) * cbar(y) * e(x, y) * (1 - F[x, y]).

    c is the soft clear (product t-norm), cbar(table) = 1, e masks self-support and padding,
    (1 - F[x, y]) removes the null move onto the current support. Table slots: cbar(slot) =
    prod_z (1 - F[z, slot]), times 1 - sum_k F[x, slot_k] (no slot-to-slot move). -> (B, N, Y).
    """
    n = batch.n
    c = column_free(F, n)  # (B, N)
    e = batch.action_mask[..., :-1].to(F.dtype)  # (B, N, Y)
    if "one" not in batch.static:
        cbar = torch.cat([c, torch.ones_like(F[:, 0, n:])], dim=-1)  # (B, Y)
        return c.unsqueeze(-1) * cbar.unsqueeze(-2) * e * (1.0 - F)
    one = batch.static["one"][:, n:].unsqueeze(-2)  # (B, 1, K) table slots
    empty = (1.0 - F[..., n:] * batch.entity_mask.unsqueeze(-1).to(F.dtype)).prod(-2)  # (B, K)
    cbar = torch.cat([c, torch.where(one[:, 0], empty, 1.0)], dim=-1)  # (B, Y)
    off = 1.0 - (F[..., n:] * one).sum(-1, keepdim=True)  # (B, N, 1): x on no slot
    if "hop" in batch.static:  # places a block may move between (`with_slots(hop=True)`)
        one = one & ~batch.static["hop"][:, None, None]
    stay = torch.cat([torch.ones_like(F[..., :n]), torch.where(one, off, 1.0)], dim=-1)
    return c.unsqueeze(-1) * cbar.unsqueeze(-2) * e * (1.0 - F) * stay


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. T_P: target exclusivity on block (and slot) columns, then row normalisation."""
    if "one" in batch.static:
        return row_normalise(exclusive_columns(F, batch.static["one"], batch.entity_mask))
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
    recursion (its fixed point on crisp towers), whatever the padding (`task.soft.log_chain`).
    """
    n = batch.n
    sweeps = batch.entity_mask.sum(-1, keepdim=True)  # (B, 1) real blocks per row
    has_goal = batch.goal.sum(-1) > 0  # (B, N)
    log_f = torch.log(F.clamp_min(torch.finfo(F.dtype).tiny))  # (B, N, Y)
    log_on_goal = (log_f * batch.goal).sum(-1)  # log F[x, g(x)], (B, N)
    if "one" in batch.static:
        log_on_goal = log_any(F, batch.goal)  # "on the table": on any slot
    return log_chain(log_f, log_on_goal, has_goal, batch.goal[..., :n], sweeps)


def tower_cross_entropy(F: Tensor, batch: SoftBatch) -> Tensor:
    """Goal cross-entropy on well-placed goal blocks: -sum_{x in goal} log w(x). -> (B,)."""
    has_goal = batch.goal.sum(-1)  # (B, N)
    return -(has_goal * log_well_placed(F, batch)).sum(-1)


GOAL_LOSSES = ("towers", "atoms")  # the first is the default


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """The goal term of the objective: ``atoms`` (the paper's CE) or ``towers`` (default).
    -> (B,)."""
    if kind == "atoms" and "one" in batch.static:  # a table goal: on any slot
        return -(log_any(F, batch.goal) * (batch.goal.sum(-1) > 0)).sum(-1)
    if kind == "atoms":
        return goal_cross_entropy(F, batch.goal)
    if kind in ("towers", "default"):
        return tower_cross_entropy(F, batch)
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")


GOAL_OR_TABLE = "goal-or-table"  # ``Problem.data`` of a window's part (`unfinished`)


def _goal_or_table(batch: SoftBatch, problems: Sequence[Problem]) -> SoftBatch:
    """``batch`` with the moves of the `GOAL_OR_TABLE` rows narrowed to onto the block's goal
    block or the table: Gupta & Nau, some shortest plan makes only constructive moves and
    moves to the table, and a block's constructive move goes to its goal support (the table
    for a block the goal leaves free). Those rows also start with STAY log(n) more likely for
    each of their n blocks (`STAY_PRIOR`): with at most three choices a block, random logits
    would have about n/1.5 blocks move at once in a step meant for one, and the step's
    competition between them (`soft_legality`) would leave each a gate near (1/3)^n."""
    rows = [i for i, p in enumerate(problems) if p.data == GOAL_OR_TABLE]
    if not rows:
        return batch
    keep = torch.ones_like(batch.action_mask)
    prior = torch.zeros(len(problems), dtype=batch.F0.dtype)
    for i in rows:
        p = problems[i]
        keep[i, :, : batch.n] = False  # block targets; the table and STAY stay
        for x, y in p.goal:
            if y != TABLE:
                keep[i, p.entities.index(x), p.entities.index(y)] = True
        prior[i] = math.log(p.n)
    static = {**batch.static, STAY_PRIOR: prior}
    return replace(batch, action_mask=batch.action_mask & keep, static=static)


def encode(
    problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """`encode_supports`; with table slots (`slotted`), a goal on the table marks every slot
    of the row and ``static["one"]`` (B, Y) marks the capacity-one columns. A window's part of
    a big problem (`GOAL_OR_TABLE`, `unfinished`) moves each block only onto its goal block or
    the table (`_goal_or_table`)."""
    if not any(slotted(p) for p in problems):
        return _goal_or_table(encode_supports(problems, states, dtype), problems)
    free = [replace(p, goal=tuple(g for g in p.goal if g[1] != TABLE)) for p in problems]
    batch = encode_supports(free, states, dtype)
    n, y = batch.n, batch.F0.shape[-1]
    one = torch.zeros(len(problems), y, dtype=torch.bool)
    for i, p in enumerate(problems):
        k = len(p.fixed)
        one[i, : p.n] = True
        one[i, n : n + k] = slotted(p)
        for x, _ in (g for g in p.goal if g[1] == TABLE):
            batch.goal[i, p.entities.index(x), n : n + (k if slotted(p) else 1)] = 1.0
    static = {**batch.static, "one": one}
    if any(hops(p) for p in problems):
        static["hop"] = torch.tensor([hops(p) for p in problems])  # (B,)
    return replace(batch, static=static)


def legal_moves(problem: Problem, state: State) -> list[Move]:
    """Every legal move in ``state``, entities in order, targets in order. Only pairs of a
    clear block and a clear target are checked (`check_move`): the others are illegal, and
    checking all N * Y pairs made the search's successor generation O(N^3)."""
    covered = set(state)
    free = [y for y in problem.targets if y == TABLE or y not in covered]
    moves = [Move(x, y) for x in problem.entities if x not in covered for y in free if y != x]
    return [m for m in moves if check_move(problem, state, m) is None]


def helpful(problem: Problem, state: State) -> frozenset[Move]:
    """The legal moves worth trying first (a greedy search's preferred moves,
    `task.symbolic.lazy_search.lazy_greedy`): a block not in position onto its goal block when
    that block is in position, or onto the table (a slot on a slotted table). Gupta & Nau: on
    the unlimited table some shortest plan makes only such moves; on slots it may have to
    park a block on another, so these are preferred, not the only ones."""
    placed, goal = in_position(problem, state), dict(problem.goal)
    slots = problem.fixed if slotted(problem) else (TABLE,)
    out = []
    for x in problem.entities:
        if x in placed:
            continue
        below = goal.get(x)
        for target in (*slots, below) if below in placed else slots:
            if check_move(problem, state, Move(x, target)) is None:  # only these are checked
                out.append(Move(x, target))
    return frozenset(out)


HOP = "hop"  # ``Problem.data`` of a slotted problem whose blocks may move place to place


def hops(problem: Problem) -> bool:
    """Whether a block may move from one slot straight to another (`with_slots` ``hop``)."""
    return slotted(problem) and problem.data == HOP


def with_slots(
    problem: Problem, slots: Sequence[str], bases: dict | None = None, hop: bool = False
) -> Problem:
    """``problem`` on a table of capacity-one ``slots`` (`slotted`): each block on the table
    stands on ``bases[block]`` (default: the slots in order, blocks in entity order).
    ``hop``: the slots are distinct places (a region's cells, table spots), so a block may move
    from one straight to another; without it such a move is illegal (it changes nothing a
    Blocksworld goal can name)."""
    rows = list(zip(problem.entities, problem.init, strict=True))
    on_table = [x for x, s in rows if s == TABLE]
    bases = dict(zip(on_table, slots, strict=False)) if bases is None else bases
    if set(slots) & {*problem.entities, TABLE} or len(set(slots)) != len(slots) or not slots:
        raise ProblemError(f"slot names {tuple(slots)} must be distinct, new and not {TABLE}")
    if len({bases.get(x) for x in on_table} & set(slots)) != len(on_table):
        raise ProblemError(f"{len(on_table)} towers need their own slots of {tuple(slots)}")
    init = tuple(bases[x] if s == TABLE else s for x, s in rows)
    return replace(problem, init=init, fixed=tuple(slots), data=HOP if hop else problem.data)


def samples(seed: int):
    """Random problems of 3 to 6 blocks, and one of 5 blocks on 4 slots when its towers fit."""
    for n_blocks in (3, 4, 5, 6):
        yield random_problem(n_blocks, seed)
    small = random_problem(5, seed + 100)
    if sum(s == TABLE for s in small.init) <= 4:
        yield with_slots(small, ("s0", "s1", "s2", "s3"))


class Blocksworld(DomainBase):
    """The blocksworld domain object the shared planner drives (see task.domains.base.Domain)."""

    name = NAME
    size_name = "blocks"
    goal_losses = GOAL_LOSSES
    # from 30 blocks the windows are ranked with moves to the table free (as Slaney and
    # Thiebaux's US), which finds the long plans of big problems faster (`PlannerConfig.parks`);
    # up to 15 blocks a plan is handed to the anytime improvement, A* below its length for at
    # most 30 s (`PlannerConfig.improve_s`): every plan of the long set optimal, PlanBench at
    # no measurable cost, 1.7x the time on 10-14-block problems (BENCHMARKS.md); from 16
    # blocks, beyond the improvement, constructive moves are taken without a window
    # (`safe_moves`), the windows deciding only which blocks to move out of the way
    planner_defaults = MappingProxyType(
        {
            "park_from": 30,
            "safe_from": 16,
            "improve_s": 30.0,
            "improve_up_to": 15,
            # a window from a deadlock (no constructive move left) must look far enough ahead
            # to see a parked block's gain: at 100 blocks 3- and 5-move windows mostly decoded
            # no move; 5 and 8 moves with half the restarts and a third of the Adam steps
            # decode 2-3 moves a window at about the same cost
            "part_window": (("horizon", 5), ("lookahead", 8), ("restarts", 8), ("iters", 20)),
        }
    )
    distributions = True
    encode = staticmethod(encode)
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
    to_actions = staticmethod(user_actions(moves_to_actions))  # the user's names
    lower_bound = staticmethod(moves_lower_bound)
    helpful = staticmethod(helpful)
    legal_moves = staticmethod(legal_moves)
    safe_moves = staticmethod(safe_moves)
    has_safe_moves = True
    unfinished = staticmethod(unfinished)
    to_atoms = staticmethod(user_atoms(to_atoms))
    to_pddl = staticmethod(to_pddl)
    from_pddl = staticmethod(from_pddl)
    samples = staticmethod(samples)
    matches = staticmethod(_pddl.matches)
    pddl_domain_text = staticmethod(_pddl.pddl_domain_text)

    @staticmethod
    def shape_key(problem: Problem) -> tuple[int, int]:
        return problem.n, len(problem.fixed)

    @staticmethod
    def size(problem: Problem) -> int:
        return problem.n


DOMAIN = Blocksworld()
