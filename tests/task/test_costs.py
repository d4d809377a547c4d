"""Move costs in the planning objective (`task.costs`): the loss term, its gradients into the
action logits and into a cost source's placements (gradcheck, float64), and the planner
preferring, among equally short plans, the one whose moves cost less."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import pytest
import torch

from task.config import PlannerConfig
from task.costs import IMPOSSIBLE
from task.domains import get_domain
from task.planner import plan
from task.problem import TABLE, Move, Problem
from task.rollout import rollout

BW = get_domain("blocksworld")
# a sits on b; the goal puts b on c, so a must go first: onto the table or onto d, 2 moves both
UNSTACK = Problem(
    "unstack", "blocksworld", ("a", "b", "c", "d"), ("b", TABLE, TABLE, TABLE), (("b", "c"),)
)
A, D, TABLE_COL = 0, 3, 4  # rows / columns of the cost matrix (targets: a, b, c, d, table)


def _setup(dtype=torch.float64):
    batch = BW.encode([UNSTACK], [BW.initial_state(UNSTACK)], dtype)
    steps = torch.ones(1, 2, dtype=torch.bool)
    gen = torch.Generator().manual_seed(0)
    shape = (1, 2, *batch.action_mask.shape[1:])  # (B, T, N, A)
    logits = torch.randn(shape, generator=gen, dtype=dtype)
    return batch, steps, logits


def test_the_motion_term_is_the_expected_cost_of_the_applied_move_mass():
    batch, steps, logits = _setup()
    config = PlannerConfig(horizon=2, lambda_motion=0.5)
    costs = torch.rand((1, 4, 5), generator=torch.Generator().manual_seed(1), dtype=torch.float64)
    plain = rollout(BW, logits, batch, steps, config)
    priced = rollout(BW, logits, batch, steps, config, costs=costs)
    expected = (priced.gates * costs[:, None]).sum()
    assert torch.allclose(priced.motion.sum(), expected)
    assert torch.allclose(priced.loss - plain.loss, 0.5 * priced.motion)


def test_gradients_flow_into_the_logits_and_the_placements_gradcheck():
    """costs(p) = |places(p) - pick|^2, a stand-in for the arm's cost with placements p."""
    batch, steps, logits = _setup()
    config = PlannerConfig(horizon=2, lambda_motion=0.7)
    picks = torch.rand((4, 2), generator=torch.Generator().manual_seed(2), dtype=torch.float64)

    def loss(lg, places):  # places: (5, 2), one per target
        costs = (places[None] - picks[:, None]).pow(2).sum(-1)[None]  # (1, N, Y)
        return rollout(BW, lg, batch, steps, config, costs=costs).loss.sum()

    places = torch.rand((5, 2), generator=torch.Generator().manual_seed(3), dtype=torch.float64)
    inputs = (logits.requires_grad_(True), places.requires_grad_(True))
    assert torch.autograd.gradcheck(loss, inputs, eps=1e-6, atol=1e-5)


@dataclass
class FixedCosts:
    """A cost source with one fixed matrix and no placements."""

    matrix: torch.Tensor
    lr: float = 0.0
    calls: list = field(default_factory=list)

    def __call__(self, indices, states, restarts):
        self.calls.append(tuple(states))
        return self

    def compute(self):
        return self.matrix

    def parameters(self):
        return []

    def commit(self, rows, moves):
        pass


EXPENSIVE = 3.0  # below IMPOSSIBLE: the decoder may take it, only the costs can steer away


@pytest.mark.parametrize("cheap", [D, TABLE_COL])
def test_among_equally_short_plans_the_cheaper_moves_win(cheap):
    matrix = torch.ones((1, 4, 5))
    matrix[0, A, D if cheap == TABLE_COL else TABLE_COL] = EXPENSIVE  # the other way for a
    assert EXPENSIVE < IMPOSSIBLE
    source = FixedCosts(matrix)
    config = PlannerConfig(lambda_motion=0.05)
    result = plan(UNSTACK, config, seed=0, costs=source)
    first = result.plan.moves[0]
    assert len(result.plan.moves) == 2 and first.entity == "a"
    assert first.target == ("d" if cheap == D else TABLE)
    assert source.calls and source.calls[0][0] == BW.initial_state(UNSTACK)


def test_the_weighted_motion_term_steers_the_logits():
    """One restart (no ranking among restarts): the task alone puts a onto d on every seed;
    with a onto d priced above a to the table, the weighted term lambda_motion * L_motion
    in the loss moves a to the table instead."""
    matrix = torch.ones((1, 4, 5))
    matrix[0, A, D] = EXPENSIVE
    for weight, target in ((0.0, "d"), (0.2, TABLE)):
        config = PlannerConfig(lambda_motion=weight, restarts=1, lookahead_share=0.0)
        for seed in range(4):
            result = plan(UNSTACK, config, seed=seed, costs=FixedCosts(matrix))
            assert result.solved and result.plan.moves[0] == Move("a", target), (weight, seed)


@dataclass
class StateCosts:
    """A cost source priced per state without placements: every move 1, a to the table
    `EXPENSIVE`, and what ``ruled_out(state)`` names (entity row, target column) `IMPOSSIBLE`."""

    lr: float = 0.0
    matrix: torch.Tensor | None = None

    def ruled_out(self, state) -> list[tuple[int, int]]:
        return []

    def __call__(self, indices, states, restarts):
        matrix = torch.ones((len(states), 4, 5))
        matrix[:, A, TABLE_COL] = EXPENSIVE
        for p, state in enumerate(states):
            for row, col in self.ruled_out(state):
                matrix[p, row, col] = IMPOSSIBLE
        self.matrix = matrix
        return self

    def compute(self):
        return self.matrix

    def parameters(self):
        return []

    def commit(self, rows, moves):
        pass


@dataclass
class AfterCosts(StateCosts):
    """Prices that depend on the state: b onto c is ruled out (`IMPOSSIBLE`) while a sits on
    d (a's body in the way of b's hand, say)."""

    def ruled_out(self, state) -> list[tuple[int, int]]:
        return [(1, 2)] if state[A] == "d" else []  # b -> c

    def price(self, state, move) -> float:
        row, col = UNSTACK.entities.index(move.entity), UNSTACK.index(move.target)
        return float(self(None, [state], 1).compute()[0, row, col])


def _priced_out_in_own_state(result, source) -> list[Move]:
    state, out = BW.initial_state(UNSTACK), []
    for move in result.plan.moves:
        if source.price(state, move) >= IMPOSSIBLE:
            out.append(move)
        state = BW.apply_move(UNSTACK, state, move)
    return out


def test_a_window_is_cut_before_a_move_priced_out_in_its_own_state():
    """The window's matrix prices b onto c in the initial state, where b is covered (the
    move is illegal there and its entry does not count): a onto d then b onto c looks
    cheapest. With `PlannerConfig.own_state_costs` the window is cut after a onto d and the
    next one, priced where b onto c would be made, moves a on; without it the plan keeps a
    move its own state rules out."""
    config = PlannerConfig(lambda_motion=0.05, horizon=3, lookahead=3, max_windows=6)
    kept = plan(UNSTACK, replace(config, own_state_costs=False), seed=0, costs=AfterCosts())
    assert kept.plan.moves == (Move("a", "d"), Move("b", "c"))  # the trap the cut avoids
    assert _priced_out_in_own_state(kept, AfterCosts()) == [Move("b", "c")]
    source = AfterCosts()
    result = plan(UNSTACK, config, seed=0, costs=source)
    assert result.solved
    assert _priced_out_in_own_state(result, source) == []
    assert result.stats["own_state_cuts"] >= 1
    assert "own_state_cuts" not in kept.stats


def test_own_state_prefix_keeps_the_first_move_and_stops_at_the_first_ruled_out():
    from task.planner.windows import own_state_prefix

    start = BW.initial_state(UNSTACK)
    moves = (Move("a", "d"), Move("b", "c"), Move("a", TABLE))
    ruled_out = {Move("b", "c"), Move("a", "d")}

    def feasible(state, move):
        return move not in ruled_out

    # the first move is the decoder's, priced in its own state there: kept
    assert own_state_prefix(BW, UNSTACK, start, moves, feasible) == (Move("a", "d"),)
    assert own_state_prefix(BW, UNSTACK, start, moves, lambda s, m: True) == moves
    # an illegal move is left to `execute`, which names it
    illegal = (Move("a", "d"), Move("d", TABLE), Move("b", "c"))  # d is under a
    assert own_state_prefix(BW, UNSTACK, start, illegal, feasible) == illegal


def test_own_state_prefix_ends_before_the_first_move_its_check_ahead_fails():
    from task.planner.windows import own_state_prefix

    start = BW.initial_state(UNSTACK)
    moves = (Move("a", "d"), Move("b", "c"))
    checked = []

    def verify(state, move):
        checked.append((state, move))
        return move != Move("b", "c")

    def fine(state, move):
        return True

    # the check ahead sees each move in the state it starts from, the first one too
    assert own_state_prefix(BW, UNSTACK, start, moves, fine, verify) == (Move("a", "d"),)
    after = BW.apply_move(UNSTACK, start, Move("a", "d"))
    assert checked == [(start, Move("a", "d")), (after, Move("b", "c"))]
    # a first move that fails its check ahead: nothing is kept
    assert own_state_prefix(BW, UNSTACK, start, moves, fine, lambda s, m: False) == ()
    # an illegal move is not checked: it is left to `execute`, which names it
    illegal = (Move("b", "c"),)  # a is on b
    assert own_state_prefix(BW, UNSTACK, start, illegal, fine, lambda s, m: False) == illegal


@dataclass
class CheckedCosts(StateCosts):
    """a onto d looks best (a to the table is `EXPENSIVE`); the source's check ahead
    (``verify``: a source of its own, not a `task.costs.CostSourceBase`) fails a onto d, which
    it then prices out in that state, as `tamp.arm.costs.ArmCosts.verify` does."""

    refused: set = field(default_factory=set)
    checked: list = field(default_factory=list)

    def ruled_out(self, state) -> list[tuple[int, int]]:
        return [
            (UNSTACK.entities.index(move.entity), UNSTACK.index(move.target))
            for s, move in self.refused
            if s == state
        ]

    def verify(self, index, state, move) -> bool:
        self.checked.append(move)
        if move == Move("a", "d"):
            self.refused.add((state, move))
            return False
        return True


def test_a_move_that_fails_the_check_ahead_is_replaced_before_anything_runs():
    """The windows decode a onto d (cheapest), the check ahead fails it, and the next window
    from the same state moves a to the table instead: the plan never holds a onto d, and
    every move it holds was checked."""
    config = PlannerConfig(lambda_motion=0.05, horizon=3, lookahead=3, max_windows=6)
    source = CheckedCosts()
    result = plan(UNSTACK, config, seed=0, costs=source)
    assert result.solved
    assert result.plan.moves == (Move("a", TABLE), Move("b", "c"))
    assert Move("a", "d") in source.checked
    assert set(result.plan.moves) <= set(source.checked)
    off = plan(UNSTACK, replace(config, own_state_costs=False), seed=0, costs=CheckedCosts())
    # the prices alone choose a onto d: the check ahead rides on own_state_costs
    assert off.plan.moves[0] == Move("a", "d")


@dataclass
class Forgets(FixedCosts):
    """A cost source of its own (not a `CostSourceBase`) that can drop its committed moves."""

    forgot: list = field(default_factory=list)

    def forget(self, index) -> None:
        self.forgot.append(index)


def test_a_cost_source_of_its_own_is_wrapped_once_with_its_optional_members():
    """Where a cost source enters the planner (`task.costs.cost_source`): one that inherits
    `CostSourceBase` is kept as it is; one that does not is wrapped, its own ``verify`` and
    ``forget`` called and ``can_forget`` telling whether it has the latter; without them the
    defaults (every move passes, nothing forgotten, no start over)."""
    from task.costs import CostSourceBase, cost_source

    assert cost_source(None) is None
    matrix = torch.ones((1, 4, 5))
    plain = cost_source(FixedCosts(matrix))
    assert isinstance(plain, CostSourceBase) and not plain.can_forget
    assert plain.verify(0, BW.initial_state(UNSTACK), Move("a", "d"))
    plain.forget(0)  # nothing to drop
    assert plain([0], [BW.initial_state(UNSTACK)], 1).compute() is matrix
    given = Forgets(matrix)
    wrapped = cost_source(given)
    assert wrapped.can_forget and cost_source(wrapped) is wrapped
    wrapped.forget(3)
    assert given.forgot == [3]
    checked = CheckedCosts()
    assert not cost_source(checked).verify(0, BW.initial_state(UNSTACK), Move("a", "d"))
    assert checked.checked == [Move("a", "d")]


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), float("-inf")])
@pytest.mark.parametrize("fallback", [False, True])
def test_a_non_finite_cost_is_refused_where_it_enters_the_planner(bad, fallback):
    """NaN or inf from a source made a solvable problem 'unsolvable' after a minute of windows
    (the windows' loss) or quietly ruled the move out (the fallback search): one line now."""
    from task.costs import finite_costs
    from task.errors import TampError

    matrix = torch.ones((1, 4, 5))
    matrix[0, A, D] = bad
    config = PlannerConfig(lambda_motion=0.05, restarts=2, iters=5, fallback=fallback)
    with pytest.raises(TampError, match=r"must be finite numbers, got (nan|inf|-inf)"):
        plan(UNSTACK, config, seed=0, costs=FixedCosts(matrix))
    with pytest.raises(TampError, match="shape \\(1, 4, 5\\)"):
        finite_costs(matrix)
    assert finite_costs(torch.full((2, 3), IMPOSSIBLE)).shape == (2, 3)
