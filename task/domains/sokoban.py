"""The Sokoban domain (PlanBench ``typed-sokoban``): the soft transition and the domain object.

The crisp side (grid tables, rules, bounds) is `task.domains.sokoban_grid`, PDDL in and out and
the samples `task.domains.sokoban_pddl`. Departures from the paper's Blocksworld equations:

- Rows of F are the robot and the boxes, each a distribution over Y = the non-wall cells
  (padded) + one last *limbo* column that holds padded box rows. A = 4 directions + STAY and only
  the robot row acts (box rows may only STAY), so there is no competition between rows.
- Eq. step (product t-norms, per robot cell r, direction d, r1 = r + d, r2 = r + 2d):
  move(r, d) = M(d) F[robot, r] none(r1);  push_b(r, d) = M(d) F[robot, r] only_b(r1) none(r2),
  with none(c) = prod_b (1 - F[b, c]) and only_b(c) = F[b, c] prod_{b' != b} (1 - F[b', c]).
  Mass leaves r (and r1 for box b) and arrives at r1 (and r2): exact on one-hot states, and the
  outflow never exceeds a row's mass (none + sum_b only_b <= 1); rows are clamped at zero
  against rounding. g(robot, d) = sum_r (move + sum_b push_b).
- Eq. T_P (cell exclusivity): F[x, c] prod_{x' != x} (1 - F[x', c]) over the robot and boxes on
  every cell column, then row normalisation (the limbo column is exempt).
- Goal "potential" (default): sum_b E[A_b(c) + C [c != goal_b]] + softmin_b E[W_b(robot, c)],
  A_b(c) the fewest actions that take box b alone from c to its goal (the robot placed best; a
  large finite value from dead cells), W_b(r, c) the extra actions when the robot starts on r
  (walking to a pushing side, round the box), C a placement bonus above any W. Goal ordering:
  a box whose goal must wait for others (`first`) adds no pull and no robot term
  until they are placed. Goal "atoms": the paper's goal cross-entropy.
- `lower_bound` is admissible (`sokoban_grid`); the domain also offers `estimate`, an
  inadmissible cost-to-go that ranks restarts far better where the planner reads it.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Sequence
from types import MappingProxyType

import torch
from torch import Tensor

from task.domains import sokoban_grid as rules
from task.domains.base import DomainBase, SoftBatch, zero_cycle_loss
from task.domains.match.renaming import user_actions, user_atoms
from task.domains.sokoban_grid import INF, ROBOT, State, grid
from task.domains.sokoban_pddl import (
    NAME,
    from_pddl,
    matches,
    pddl_domain_text,
    samples,
    to_actions,
    to_atoms,
    to_pddl,
)
from task.errors import ProblemError, one_of
from task.problem import Move, Problem
from task.soft import goal_cross_entropy, row_normalise

GOAL_LOSSES = ("potential", "atoms")

# --------------------------------------------------------------------------------- ranking


def first(problem: Problem, state: State) -> dict[int, set[int]]:
    """Goal ordering: box -> the boxes that must reach their goals first (box a goes before b
    when b's goal as a wall leaves a no way to its own goal; mutual pairs are dropped)."""
    g, goal = grid(problem), rules.goals(problem)
    at = [g.index[c] for c in state[1:]]

    def blocks(b: int, a: int) -> bool:
        table = g.push_dist(goal[a], frozenset({goal[b]}))
        return at[a] != goal[b] and not table[at[a]] and bool(g.push_dist(goal[a])[at[a]])

    pairs = {b: {a for a in goal if a != b and blocks(b, a)} for b in goal}
    return {b: {a for a in s if b not in pairs[a]} for b, s in pairs.items()}


def _placed_cost(g, goal: int, c: int, r: int, walls: set[int]) -> float:
    """Fewest actions that take the box on c to ``goal`` from the robot on r with the ``walls``
    cells filled (A* over box x robot cells guided by the exact obstacle-free
    `Grid.lone_cost`); after 4000 expansions, the least f still open (a bound)."""
    lone, best = g.lone_cost(goal), {(c, r): 0}
    heap = [(lone[c][r], 0, c, r)] if lone[c][r] < INF else []
    for _ in range(4000):
        if not heap or heap[0][2] == goal:
            return heap[0][1] if heap else INF
        _, t, c, r = heapq.heappop(heap)
        for d, q in enumerate(g.nbr[r] if t == best[(c, r)] else ()):
            nxt = (g.nbr[c][d], c) if q == c else (c, q)  # a push, or a step
            if q < 0 or q in walls or nxt[0] < 0 or nxt[0] in walls:
                continue
            if t + 1 < best.get(nxt, INF) and lone[nxt[0]][nxt[1]] < INF:
                best[nxt] = t + 1
                heapq.heappush(heap, (t + 1 + lone[nxt[0]][nxt[1]], t + 1, *nxt))
    return heap[0][0] if heap else INF


def estimate(problem: Problem, state: State) -> float:
    """A cost-to-go estimate for ranking (not admissible): the boxes placed one after another,
    in the best order the goal ordering allows; the first box with the others where they stand
    (`_placed_cost`), the rest alone (`Grid.lone_cost`), each from where the last one ended
    (all alone + 8 when every first box is walled in). INF at a dead end, >= `lower_bound`."""
    g, bound, key = grid(problem), rules.lower_bound(problem, state), ("estimate", tuple(state))
    if key not in g.cache and 0 < bound < INF:
        at, goal, robot = [g.index[c] for c in state[1:]], rules.goals(problem), g.index[state[0]]
        before, todo = first(problem, state), [k for k, c in goal.items() if at[k] != c]
        orders = list(itertools.permutations(todo))
        fine = [
            o
            for o in orders
            if all(o.index(a) < o.index(b) for b in o for a in before[b] if a in o)
        ] or orders
        heads = {o[0] for o in fine}
        walled = {k: _placed_cost(g, goal[k], at[k], robot, set(at) - {at[k]}) for k in heads}
        alone = {k: g.lone_cost(goal[k])[at[k]][robot] for k in heads}

        def chain(order: tuple[int, ...], head: dict[int, float]) -> float:
            t, where = head[order[0]], rules.ends(g, goal[order[0]])
            for k in order[1:]:
                t += min(g.lone_cost(goal[k])[at[k]][r] for r in where)
                where = rules.ends(g, goal[k])
            return t

        best = min(chain(o, walled) for o in fine)
        best = best if best < INF else min(chain(o, alone) for o in fine) + 8
        g.cache[key] = max(best, bound)
    return g.cache.get(key, bound)


# ------------------------------------------------------------------------------------- soft


def _tables(problem: Problem) -> tuple[Tensor, ...]:
    """Static tensors of a problem (float64, cached): nbr (D, C) cell ahead (-1: none); per box
    pot (K, C) its potential when ready, wait (K, C) when not (dead cells only), and walk
    (K, C_robot, C_box) the robot's extra cost W_k (module doc)."""
    g = grid(problem)
    if "soft" in g.cache:
        return g.cache["soft"]
    C, D, K = len(g.cells), len(g.dirs), problem.n - 1
    nbr = torch.tensor(g.nbr, dtype=torch.long).reshape(C, D).T  # (D, C)
    costs = {b: torch.tensor(g.lone_cost(g.index[c]), dtype=torch.float64) for b, c in problem.goal}
    best = {b: t.amin(1) for b, t in costs.items()}  # (C,) the box's cost, robot placed best
    extra = [(t - best[b][:, None]).T for b, t in costs.items()]  # (C_r, C_c)
    bonus = max([x[x < INF].max().item() for x in extra if (x < INF).any()], default=0.0) + 2
    pot, wait = torch.zeros(K, C, dtype=torch.float64), torch.zeros(K, C, dtype=torch.float64)
    walk = torch.full((K, C, C), bonus, dtype=torch.float64)
    for (box, cell), x in zip(problem.goal, extra, strict=True):
        k, j, a = problem.entities.index(box) - 1, g.index[cell], best[box]
        walk[k] = torch.where(x < INF, x, bonus)
        walk[k, :, j] = bonus
        dead = 4 * bonus + 2 * torch.where(a < INF, a, 0.0).max().item()
        pot[k], wait[k] = torch.where(a < INF, a + bonus, dead), torch.where(a < INF, 0.0, dead)
        pot[k, j] = 0.0
    g.cache["soft"] = (nbr, pot, wait, walk)
    return g.cache["soft"]


def ready(problem: Problem, state: State) -> list[bool]:
    """Per box: whether the boxes that must reach their goals first are there (all boxes when
    no unplaced box would be ready)."""
    at, before = state[1:], first(problem, state)
    goal = {problem.entities.index(b) - 1: c for b, c in problem.goal}
    out = [all(at[a] == goal[a] for a in before.get(k, ())) for k in range(len(at))]
    return out if any(out[k] and at[k] != c for k, c in goal.items()) else [True] * len(at)


def encode(
    problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """One-hot cells of every entity, padded: N = 1 + boxes rows, Y = cells + 1 (limbo last)."""
    b, n = len(problems), max(p.n for p in problems)
    y = max(len(p.fixed) for p in problems) + 1
    F0, goal = torch.zeros(b, n, y, dtype=dtype), torch.zeros(b, n, y, dtype=dtype)
    F0[:, :, -1] = 1.0  # padded boxes rest in limbo
    entity, mask = torch.zeros(b, n, dtype=torch.bool), torch.zeros(b, n, 5, dtype=torch.bool)
    mask[..., -1] = True
    nxt = torch.arange(y).repeat(b, 4, 1)  # (B, 4, Y): no neighbour -> itself, not ok
    ok = torch.zeros(b, 4, y, dtype=dtype)
    pot, cell = torch.zeros(b, n, y, dtype=dtype), torch.zeros(b, 1, y, dtype=torch.bool)
    bonus = [_tables(p)[3].max().item() if p.n > 1 else 0.0 for p in problems]
    walk = torch.tensor(bonus, dtype=dtype)[:, None, None, None].repeat(1, n - 1, y, y)
    for i, (p, s) in enumerate(zip(problems, states, strict=True)):
        g, c = grid(p), len(p.fixed)
        F0[i, : p.n] = 0.0
        F0[i, torch.arange(p.n), [g.index[x] for x in s]] = 1.0
        for box, at in p.goal:
            goal[i, p.entities.index(box), g.index[at]] = 1.0
        entity[i, : p.n], mask[i, 0, : len(g.dirs)], cell[i, 0, :c] = True, True, True
        nbr, pt, wt, wk = _tables(p)
        on = torch.tensor(ready(p, s), dtype=torch.bool)[:, None]  # (K, 1)
        d = len(g.dirs)
        nxt[i, :d, :c] = torch.where(nbr >= 0, nbr, torch.arange(c))
        ok[i, :d, :c] = (nbr >= 0).to(dtype)
        pot[i, 1 : p.n, :c] = torch.where(on, pt, wt).to(dtype)
        walk[i, : p.n - 1, :c, :c] = torch.where(on[:, :, None], wk, bonus[i]).to(dtype)
    ok2 = ok * ok.gather(2, nxt)  # (B, 4, Y) two cells ahead exist
    static = {
        "nxt": nxt,
        "nxt2": nxt.gather(2, nxt),
        "ok": ok,
        "ok2": ok2,
        "pot": pot,
        "walk": walk,
        "cell": cell,
    }
    return SoftBatch(F0, entity, mask, goal, static)


def _others(v: Tensor) -> Tensor:
    """out[:, x] = prod_{x' != x} v[:, x'] over the few rows (plain products, exact at 0 and
    cheap to differentiate): (B, N, Y) -> (B, N, Y)."""
    rows = v.unbind(1)
    out = [
        math.prod((r for j, r in enumerate(rows) if j != x), start=torch.ones_like(rows[x]))
        for x in range(len(rows))
    ]
    return torch.stack(out, 1) if out else v


def step(F: Tensor, M: Tensor, batch: SoftBatch) -> tuple[Tensor, Tensor]:
    """Eq. step of the module doc: F (B, N, Y), M (B, N, 5) -> F', g (B, N, 4)."""
    s = batch.static
    nxt, nxt2, ok, ok2 = s["nxt"], s["nxt2"], s["ok"], s["ok2"]  # (B, 4, Y)
    R, X = F[:, 0], F[:, 1:]  # (B, Y), (B, K, Y)
    b, k, y = X.shape
    empty = 1.0 - X
    none = empty.prod(1)[:, None].expand(b, 4, y)  # (B, 4, Y) no box on the cell
    only = X * _others(empty)  # (B, K, Y) box k alone on the cell
    idx, idx2 = nxt[:, :, None].expand(b, 4, k, y), nxt2[:, :, None].expand(b, 4, k, y)
    only1 = only[:, None].expand(b, 4, k, y).gather(3, idx) * ok[:, :, None]  # (B, 4, K, Y)
    ar = M[:, 0, :4, None] * R[:, None]  # (B, 4, Y) robot mass choosing each direction
    push = ar[:, :, None] * only1 * (none.gather(2, nxt2) * ok2)[:, :, None]  # (B, 4, K, Y)
    go = ar * none.gather(2, nxt) * ok + push.sum(2)  # (B, 4, Y) robot mass leaving r
    R1 = (R - go.sum(1)).clamp_min(0.0) + torch.zeros_like(R).scatter_add(
        1, nxt.flatten(1), go.flatten(1)
    )
    flat = push.transpose(1, 2).reshape(b, k, 4 * y)  # (B, K, 4Y)
    out = torch.zeros_like(X).scatter_add(2, idx.transpose(1, 2).reshape(b, k, -1), flat)
    into = torch.zeros_like(X).scatter_add(2, idx2.transpose(1, 2).reshape(b, k, -1), flat)
    g = torch.zeros(b, F.shape[1], 4, dtype=F.dtype, device=F.device)
    g[:, 0] = go.sum(-1)
    return torch.cat([R1[:, None], (X - out).clamp_min(0.0) + into], dim=1), g


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """Eq. T_P: cell exclusivity (product t-norm) over all rows, then row normalisation."""
    others = _others(1.0 - F)  # (B, N, Y)
    return row_normalise(torch.where(batch.static["cell"], F * others, F))


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """``potential`` (default, module doc) or ``atoms`` (the paper's goal CE). -> (B,)."""
    if kind == "atoms":
        return goal_cross_entropy(F, batch.goal)
    if kind not in ("potential", "default"):
        raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")
    boxes = (F * batch.static["pot"]).sum((1, 2))
    if F.shape[1] == 1:
        return boxes
    walk = (batch.static["walk"] @ F[:, 1:, :, None]).squeeze(-1)  # (B, K, Y) per robot cell
    return boxes - torch.logsumexp(-(walk * F[:, :1]).sum(-1), dim=-1)


# ----------------------------------------------------------------------------------- object


def decode(problem: Problem, row: int, col: int, n: int) -> Move | None:
    dirs = grid(problem).dirs
    return Move(ROBOT, dirs[col]) if row == 0 and col < len(dirs) else None


class Sokoban(DomainBase):
    """The Sokoban domain object the shared planner drives (see task.domains.base.Domain)."""

    name = NAME
    size_name = "boxes"
    goal_losses = GOAL_LOSSES
    distributions = True
    encode = staticmethod(encode)
    step = staticmethod(step)
    consistency = staticmethod(consistency)
    cycle_loss = staticmethod(zero_cycle_loss)
    goal_loss = staticmethod(goal_loss)
    decode = staticmethod(decode)
    initial_state = staticmethod(rules.initial_state)
    check_move = staticmethod(rules.check_move)
    apply_move = staticmethod(rules.apply_move)
    legal_moves = staticmethod(rules.legal_moves)
    is_goal = staticmethod(rules.is_goal)
    lower_bound = staticmethod(rules.lower_bound)
    from_pddl = staticmethod(from_pddl)
    to_actions = staticmethod(user_actions(to_actions))  # the user's names
    to_atoms = staticmethod(user_atoms(to_atoms))
    to_pddl = staticmethod(to_pddl)
    samples = staticmethod(samples)
    matches = staticmethod(matches)
    pddl_domain_text = staticmethod(pddl_domain_text)
    estimate = staticmethod(estimate)
    has_estimate = True
    # PlannerConfig.for_domain: pushes are irreversible and plans run to 65 actions, so
    # longer lookahead restarts (8 moves) and a larger window budget (see BENCHMARKS.md)
    planner_defaults = MappingProxyType({"lookahead": 8, "max_windows": 100})

    @staticmethod
    def shape_key(problem: Problem) -> int:
        """Cells rounded up to a multiple of 32 (the walk table grows as cells squared)."""
        return -(-len(problem.fixed) // 32)

    @staticmethod
    def size(problem: Problem) -> int:
        return problem.n - 1


DOMAIN = Sokoban()
