"""The interface a planning domain supplies, and the tensor encoding shared by relational domains.

A domain is one file in ``task/domains/`` exposing an object that satisfies `Domain` (its class
inherits `DomainBase`, the defaults of the optional members): its soft
transition (``step``, ``consistency``), its action columns and how a column decodes into a
move, its crisp legality and apply, its goal terms, an admissible lower bound, its PDDL
mapping and a sampler of small problems for the contract tests. The rollout, optimiser,
decoder and replanning windows (``task.rollout``, ``task.optimize``, ``task.decode``,
``task.planner``) are shared and never change per domain.

Shapes: a state tensor is ``F: (B, N, Y)`` (N rows, e.g. entities; Y columns, e.g. support
targets), an action distribution ``M: (B, N, A)`` per row whose last column is STAY, and the
applied move mass ``g: (B, N, A - 1)``, one entry per non-STAY action column. Relational
domains (Blocksworld, Logistics) use ``Y = N + K`` support targets and ``A = Y + 1``
(`encode_supports`, `relational_step`); other domains choose their own Y and A.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Protocol

import torch
from pddl.core import Domain as PDDLDomain
from pddl.core import Problem as PDDLProblem
from torch import Tensor

from task.deadline import NO_DEADLINE, Deadline
from task.problem import Action, Move, Problem
from task.soft import transition

State = tuple | frozenset  # crisp: supports per entity (relational), or a set of atoms
STAY_PRIOR = "stay-prior"  # ``SoftBatch.static`` key, (B,): a row's STAY logit offset at the
# start of a window (`task.optimize.initial_logits`), as a log-odds factor; absent: none
INF = math.inf  # the lower bound of a dead end: no sequence of moves reaches the goal


@dataclass(frozen=True)
class SoftBatch:
    """Padded tensors for B problems of one domain.

    ``static`` holds the domain's per-problem constant tensors (adjacency, city masks,
    preconditions), batch first; `repeat` repeats them with the rest.
    """

    F0: Tensor  # (B, N, Y) crisp initial state, one-hot
    entity_mask: Tensor  # (B, N) bool, real rows
    action_mask: Tensor  # (B, N, A) bool, last column STAY (always allowed)
    goal: Tensor  # (B, N, Y) one-hot goal atoms, zero rows for entities the goal leaves free
    static: dict[str, Tensor] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.F0.shape[1]

    def repeat(self, r: int) -> SoftBatch:
        """Each problem ``r`` times in a row (restarts): (B, ...) -> (B * r, ...)."""
        rep = {k: v.repeat_interleave(r, dim=0) for k, v in self.static.items()}
        return SoftBatch(*(t.repeat_interleave(r, dim=0) for t in self.astuple()), static=rep)

    def astuple(self) -> tuple[Tensor, Tensor, Tensor, Tensor]:
        return (self.F0, self.entity_mask, self.action_mask, self.goal)


def encode_supports(
    problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """One-hot support tensors for problems whose targets are entities + fixed targets.

    Both axes are padded: ``N`` entity slots, then ``K`` fixed-target slots, so the first fixed
    target sits at column ``N`` for every problem. Padded entities rest on the first fixed
    target, may only STAY and are never targets; padded fixed targets are never targets. A
    domain narrows ``action_mask`` further with its own static legality.
    """
    n = max(p.n for p in problems)
    k = max(len(p.fixed) for p in problems)
    b, y = len(problems), n + k
    F0 = torch.zeros(b, n, y, dtype=dtype)
    goal = torch.zeros(b, n, y, dtype=dtype)
    entity = torch.zeros(b, n, dtype=torch.bool)
    target = torch.zeros(b, y, dtype=torch.bool)
    for i, (p, s) in enumerate(zip(problems, states, strict=True)):
        col = {name: j for j, name in enumerate(p.entities)}
        col.update({name: n + j for j, name in enumerate(p.fixed)})
        F0[i, torch.arange(n), n] = 1.0  # padding rests on the first fixed target
        for x, sup in enumerate(s):
            F0[i, x] = 0.0
            F0[i, x, col[sup]] = 1.0
        for x, sup in p.goal:
            goal[i, col[x], col[sup]] = 1.0
        entity[i, : p.n] = True
        target[i, : p.n] = True
        target[i, n : n + len(p.fixed)] = True
    not_self = ~torch.eye(n, y, dtype=torch.bool)  # (N, Y)
    moves = entity[:, :, None] & target[:, None, :] & not_self  # (B, N, Y)
    stay = torch.ones(b, n, 1, dtype=torch.bool)
    return SoftBatch(F0, entity, torch.cat([moves, stay], dim=-1), goal)


def relational_step(
    legality: Callable[[Tensor, SoftBatch], Tensor],
) -> Callable[[Tensor, Tensor, SoftBatch], tuple[Tensor, Tensor]]:
    """The support-relation step ``F' = (1 - m) F + g`` (`task.soft.transition`) gated by a
    domain's soft ``legality(F, batch) -> (B, N, Y)``: one row changes per committed move."""

    def step(F: Tensor, M: Tensor, batch: SoftBatch) -> tuple[Tensor, Tensor]:
        return transition(F, M, legality(F, batch))

    return step


def relational_decode(problem: Problem, row: int, col: int, n: int) -> Move | None:
    """Column ``col`` of entity row ``row`` as ``move(entity -> target)`` (None on padding);
    ``n`` is the padded entity count (targets: entities 0..n-1, fixed targets from n)."""
    if row >= problem.n:
        return None
    if col < n:
        return Move(problem.entities[row], problem.entities[col]) if col < problem.n else None
    k = col - n
    return Move(problem.entities[row], problem.fixed[k]) if k < len(problem.fixed) else None


def zero_cycle_loss(F: Tensor, batch: SoftBatch) -> Tensor:
    """No cycle term (domains whose relation cannot form cycles): (B, N, Y) -> (B,) zeros."""
    return F.new_zeros(F.shape[0])


class Domain(Protocol):
    """What a domain file provides. Tensors are batch first; see the glossary in ``task``.

    Optional, with defaults in `DomainBase` (which a domain's class inherits): ``estimate``,
    an inadmissible cost-to-go the decoder ranks restarts by instead of ``lower_bound``
    (which still marks dead ends), where ``has_estimate``; ``helpful`` moves the greedy search
    tries first; ``planner_defaults``, `PlannerConfig` fields (`PlannerConfig.for_domain`);
    for big problems (`PlannerConfig.safe_from`), ``safe_moves``, moves some shortest plan
    starts with, taken without a window where ``has_safe_moves``, and ``unfinished``, the part
    of the problem a window of at most ``depth`` moves plans (`window_part`)."""

    name: str
    size_name: str  # what `size` counts, a table's column head ("blocks", "packages", ...)
    goal_losses: tuple[str, ...]  # accepted goal-loss kinds; "default" resolves to the first
    distributions: bool  # rows of F are distributions (False: independent atom probabilities)

    # ------------------------------------------------------------------ tensors (soft side)
    def shape_key(self, problem: Problem) -> Hashable:
        """Problems with equal keys share one tensor program (sortable: int or int tuple)."""
        ...

    def encode(
        self, problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype
    ) -> SoftBatch: ...

    def step(self, F: Tensor, M: Tensor, batch: SoftBatch) -> tuple[Tensor, Tensor]:
        """One soft transition: F (B, N, Y), M (B, N, A) -> (F', g) with g (B, N, A - 1) the
        move mass applied per action column. One-hot F and M give the crisp successor."""
        ...

    def consistency(self, F: Tensor, batch: SoftBatch) -> Tensor:
        """The domain's T_P consistency operator (one application), (B, N, Y) -> (B, N, Y)."""
        ...

    def cycle_loss(self, F: Tensor, batch: SoftBatch) -> Tensor:
        """Penalty on direct two-cycles in the relation, (B, N, Y) -> (B,)."""
        ...

    def goal_loss(self, F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
        """Goal term of the objective, (B, N, Y) -> (B,); ``kind`` is one of ``goal_losses``
        (or "default"); "atoms" is the paper's cross-entropy on the goal atoms."""
        ...

    def decode(self, problem: Problem, row: int, col: int, n: int) -> Move | None:
        """The move of action column ``col`` of row ``row`` (None for padding); ``n``: the
        batch's padded row count ``F.shape[1]``."""
        ...

    # ------------------------------------------------------------------------- crisp side
    def initial_state(self, problem: Problem) -> State: ...

    def check_move(self, problem: Problem, state: State, move: Move) -> str | None:
        """None when ``move`` is legal in ``state``, else a one-line reason."""
        ...

    def apply_move(self, problem: Problem, state: State, move: Move) -> State: ...

    def legal_moves(self, problem: Problem, state: State) -> list[Move]:
        """Every legal move in ``state`` (samplers' random walks, tests)."""
        ...

    def is_goal(self, problem: Problem, state: State) -> bool: ...

    def lower_bound(self, problem: Problem, state: State) -> float:
        """An admissible lower bound on the moves still needed; `INF` at a dead end."""
        ...

    def size(self, problem: Problem) -> int:
        """The problem's size in ``size_name`` units."""
        ...

    # ------------------------------------------------------------------------------- PDDL
    def matches(self, domain: PDDLDomain) -> bool:
        """Whether the parsed PDDL domain is this domain (recognition, ``--domain-rules``)."""
        ...

    def from_pddl(
        self,
        domain: PDDLDomain,
        problem: PDDLProblem,
        order: Sequence[str],
        deadline: Deadline = NO_DEADLINE,
    ) -> Problem:
        """The relational problem of a parsed PDDL problem; ``order``: objects in file order.
        Raises PDDLError naming what does not fit the domain. ``deadline``: a command's
        (`task.deadline`); a domain that grounds the problem (the generic lift) stops at it
        with `TimeLimitReached`, one that reads it in linear time may ignore it."""
        ...

    def to_actions(
        self, problem: Problem, moves: Sequence[Move], strict: bool = True
    ) -> tuple[Action, ...]:
        """The domain's PDDL actions for a sequence of moves (its PDDL mapping);
        ``strict=False`` also translates illegal moves, for a validator to find. A problem read
        from a renamed domain (``problem.renaming``) gets the user's names: wrap the mapping in
        `task.domains.match.renaming.user_actions`."""
        ...

    def to_atoms(self, problem: Problem, state: State) -> frozenset[tuple[str, ...]]:
        """The PDDL atoms (fluent and static) that hold in ``state``, lowercased; in the
        user's names for a renamed domain's problem (`task.domains.match.renaming.user_atoms`)."""
        ...

    def to_pddl(self, problem: Problem) -> str:
        """Problem PDDL text for ``problem`` (the domain file is ``pddl_domain_text()``)."""
        ...

    def pddl_domain_text(self) -> str: ...

    def samples(self, seed: int) -> Iterator[Problem]:
        """Small random problems of this domain of several sizes, for the contract tests."""
        ...

    # ----------------------------------------------------- optional (defaults: `DomainBase`)
    planner_defaults: Mapping[str, object]
    has_estimate: bool
    has_safe_moves: bool

    def estimate(self, problem: Problem, state: State) -> float: ...

    def helpful(self, problem: Problem, state: State) -> frozenset: ...

    def safe_moves(self, problem: Problem, state: State) -> Sequence[Move]: ...

    def unfinished(
        self, problem: Problem, state: State, depth: int | None
    ) -> tuple[Problem, Sequence[int]] | None: ...


class DomainBase:
    """The defaults of a `Domain`'s optional members; every domain's class inherits it, so
    the planner calls these members directly. A domain overrides what it has (with a
    ``staticmethod``, as its other members) and sets the flag that says so."""

    planner_defaults: Mapping[str, object] = MappingProxyType({})  # `PlannerConfig.for_domain`
    has_estimate = False  # whether `estimate` is the domain's own (else the lower bound)
    has_safe_moves = False  # whether `safe_moves` may name any (`PlannerConfig.safe_from`)

    def estimate(self, problem: Problem, state: State) -> float:
        """An inadmissible cost-to-go to rank by (the decoder's restarts, the greedy search);
        by default the admissible ``lower_bound``."""
        return self.lower_bound(problem, state)

    def helpful(self, problem: Problem, state: State) -> frozenset:
        """Moves the greedy search tries first from ``state`` (its preferred queue,
        `task.symbolic.lazy_search.lazy_greedy`); by default none."""
        return frozenset()

    def safe_moves(self, problem: Problem, state: State) -> Sequence[Move]:
        """Moves some shortest plan from ``state`` starts with, taken without a window
        (`task.planner.windows.take_safe`, where ``has_safe_moves``); by default none."""
        return ()

    def unfinished(
        self, problem: Problem, state: State, depth: int | None
    ) -> tuple[Problem, Sequence[int]] | None:
        """The part of ``problem`` a window of at most ``depth`` moves plans from ``state``,
        with the kept entities' indices (`window_part`); by default None, the whole."""
        return None


def window_part(
    domain: Domain, problem: Problem, state: State, visited: set, depth: int | None = None
) -> tuple[Problem, State, set]:
    """The problem a window of at most ``depth`` moves plans from ``state``: the domain's part
    still to be planned (its ``unfinished(problem, state, depth) -> (part, kept indices) |
    None``; the part may have entities of its own after the kept ones, and keep
    only what ``depth`` moves can change), the part's state and ``visited`` read in the part's
    blocks and supports. Of the visited states only those a window could reach again are
    read: the same as now in every block the part drops or stands elsewhere (the window moves
    neither), each then read in the part as it stands now. The window's moves are moves of the
    whole problem, and its goal is reached exactly when the whole one's is. ``problem``,
    ``state`` and ``visited`` as they are without such a part or when it has no goal left."""
    part = domain.unfinished(problem, state, depth)
    if part is None or not part[0].goal:
        return problem, state, visited
    part, keep = part
    fixed = [i for j, i in enumerate(keep) if state[i] != part.init[j]]  # stands elsewhere
    fixed += sorted(set(range(len(state))) - set(keep))  # dropped
    own = part.init[len(keep) :]  # the part's own entities stand still
    seen = {
        tuple(part.init[j] if state[i] != part.init[j] else past[i] for j, i in enumerate(keep))
        + own
        for past in visited
        if all(past[i] == state[i] for i in fixed)
    }
    return part, part.init, seen


def resolve_goal_loss(domain: Domain, kind: str) -> str:
    """``kind``, with "default" replaced by the domain's first goal loss."""
    return domain.goal_losses[0] if kind == "default" else kind
