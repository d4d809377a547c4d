"""The complete fallback (`task.symbolic.lazy_search`) and its hook in the receding planner:
lazy feasibility checks, SOLVED / UNSOLVABLE / BUDGET, and plans that always validate."""

from __future__ import annotations

import itertools
import time
import zlib
from collections import deque
from dataclasses import dataclass, field

import pytest
import torch

from task.config import PlannerConfig
from task.costs import IMPOSSIBLE, CostSourceBase
from task.domains import get_domain, names
from task.errors import TampError
from task.planner import plan
from task.planner.windows import execute
from task.problem import TABLE, Move, PlanStatus, Problem
from task.symbolic.generate import random_problem
from task.symbolic.lazy_search import SearchStatus, lazy_best_first
from task.symbolic.search import optimal_moves
from tests.pddl_check import assert_valid

BW = get_domain("blocksworld")
CHEAP = PlannerConfig(restarts=2, iters=15, max_windows=4)
# a, b, c, d on the table; the goal: a on b
FLAT = Problem("flat", "blocksworld", ("a", "b", "c", "d"), (TABLE,) * 4, (("a", "b"),))
STATES_OF_FOUR = 73  # blocksworld states of four blocks (towers of labelled blocks)


def needs_d_on_c(state, move) -> bool:
    """The arm cannot take a onto b until d stands on c (ruled out there, not for good)."""
    return move == Move("a", "b") and state[3] != "c"


def never_a_on_b(state, move) -> bool:
    return move == Move("a", "b")


@dataclass
class RuleOut(CostSourceBase):
    """A fake cost source: every move costs 1, the ones ``rule(state, move)`` names cost
    IMPOSSIBLE; records the moves committed to it."""

    problem: Problem
    rule: object
    lr: float = 0.0
    committed: list = field(default_factory=list)

    def __call__(self, indices, states, restarts):
        ys = self.problem.targets
        self.matrix = torch.ones(len(states), self.problem.n, len(ys))  # (P, N, Y)
        for k, s in enumerate(states):
            for (i, x), (j, y) in itertools.product(
                enumerate(self.problem.entities), enumerate(ys)
            ):
                if self.rule(s, Move(x, y)):
                    self.matrix[k, i, j] = IMPOSSIBLE
        return self

    def compute(self):
        return self.matrix

    def parameters(self):
        return []

    def commit(self, rows, moves):
        self.committed.extend(m for done in moves for m in done)


def _replay_allowed(problem, moves, rule) -> bool:
    """Whether no move of ``moves`` is ruled out in the state it starts from."""
    state = BW.initial_state(problem)
    for move in moves:
        if rule(state, move):
            return False
        state = BW.apply_move(problem, state, move)
    return True


# ------------------------------------------------------------------------- the search alone


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_without_rule_outs_the_search_is_a_star(n):
    """Nothing ruled out, weight 1: as short as the reference A* (`optimal_moves`)."""
    for seed in range(3):
        problem = random_problem(n, seed)
        found = lazy_best_first(BW, problem, BW.initial_state(problem))
        assert found.status is SearchStatus.SOLVED
        assert len(found.moves) == len(optimal_moves(problem))
        assert_valid(problem, found.moves)


def test_feasibility_is_checked_lazily_and_cached():
    """Only popped moves are checked, each once; a move ruled out in one state is pruned
    there only: a onto b is taken after d moved onto c."""
    calls = []

    def feasible(state, move):
        calls.append((state, move))
        return not needs_d_on_c(state, move)

    found = lazy_best_first(BW, FLAT, BW.initial_state(FLAT), feasible)
    assert found.status is SearchStatus.SOLVED
    assert found.moves == (Move("d", "c"), Move("a", "b"))
    assert len(calls) == len(set(calls)) == found.checked
    every = {(s, m) for s in _reachable(FLAT, None) for m in BW.legal_moves(FLAT, s)}
    assert len(calls) < len(every) / 4  # most moves never need a check
    assert found.ruled_out >= 1 and Move("a", "b") in {m for _, m in calls}


def _reachable(problem, rule) -> set:
    """Every state reachable with the moves ``rule`` allows (None: all), breadth first."""
    start = BW.initial_state(problem)
    seen, queue = {start}, deque([start])
    while queue:
        state = queue.popleft()
        for move in BW.legal_moves(problem, state):
            nxt = BW.apply_move(problem, state, move)
            if (rule is None or not rule(state, move)) and nxt not in seen:
                seen.add(nxt)
                queue.append(nxt)
    return seen


def test_an_impossible_goal_is_unsolvable_within_these_choices():
    found = lazy_best_first(BW, FLAT, BW.initial_state(FLAT), _negated(never_a_on_b))
    assert found.status is SearchStatus.UNSOLVABLE and found.moves == ()
    assert found.expanded == len(_reachable(FLAT, never_a_on_b)) == STATES_OF_FOUR - 13
    assert "no plan exists within these choices" in found.reason
    assert found.ruled_out > 0 and f"{found.ruled_out} moves ruled out" in found.reason


def test_the_budget_and_the_deadline_stop_the_search():
    problem = random_problem(6, 0)
    start = BW.initial_state(problem)
    assert lazy_best_first(BW, problem, start, max_nodes=1).status is SearchStatus.BUDGET
    past = time.perf_counter() - 1.0
    late = lazy_best_first(BW, problem, start, deadline=past)
    assert late.status is SearchStatus.BUDGET and late.expanded == 0 and "time" in late.reason


def _hashed_rule(seed: int, share: float):
    """A deterministic random rule-out: about ``share`` of all (state, move) pairs."""

    def rule(state, move) -> bool:
        key = f"{seed}|{state}|{move}".encode()
        return zlib.crc32(key) % 1000 < share * 1000

    return rule


def _negated(rule):
    return lambda state, move: not rule(state, move)


@pytest.mark.parametrize(
    ("share", "seen"),
    [(0.3, SearchStatus.SOLVED), (0.6, SearchStatus.SOLVED), (0.9, SearchStatus.UNSOLVABLE)],
)
def test_every_plan_validates_and_unsolvable_means_unreachable(share, seen):
    """Random rule-outs on random problems: a SOLVED plan passes the PDDL validator and uses
    no ruled-out move; UNSOLVABLE agrees with an independent breadth-first search."""
    outcomes = set()
    for n, seed in itertools.product((3, 4), range(4)):
        problem = random_problem(n, seed)
        rule = _hashed_rule(seed, share)
        allowed = _negated(rule)
        found = lazy_best_first(BW, problem, BW.initial_state(problem), allowed)
        reachable = _reachable(problem, rule)
        goal_reachable = any(BW.is_goal(problem, s) for s in reachable)
        outcomes.add(found.status)
        if found.status is SearchStatus.SOLVED:
            assert_valid(problem, found.moves)
            assert _replay_allowed(problem, found.moves, rule)
        else:
            assert found.status is SearchStatus.UNSOLVABLE and not goal_reachable
            assert found.expanded == len(reachable)
    assert seen in outcomes


@pytest.mark.parametrize("name", names())
def test_the_search_runs_on_every_registered_domain(name):
    """Generic over the domain interface: a plan found replays legally to the goal."""
    domain = get_domain(name)
    problem = next(iter(domain.samples(0)))
    state = domain.initial_state(problem)
    found = lazy_best_first(domain, problem, state, max_nodes=5_000)
    assert found.status is SearchStatus.SOLVED
    for move in found.moves:
        assert domain.check_move(problem, state, move) is None
        state = domain.apply_move(problem, state, move)
    assert domain.is_goal(problem, state)


# ------------------------------------------------------------------- the hook in the planner


def test_a_move_back_to_a_visited_state_is_a_cycle():
    start = BW.initial_state(FLAT)
    visited = {start}
    there = (Move("a", "c"),)
    back = (Move("a", TABLE),)
    _, state, _, looped = execute(BW, FLAT, start, there, visited)
    assert not looped
    _, state, _, looped = execute(BW, FLAT, state, back, visited)
    assert looped and state == start


def test_the_fallback_takes_over_when_the_windows_cycle():
    """The windows want a onto b, ruled out until d stands on c: on this seed they go a -> c,
    b -> d, b -> table (back to a state they visited), and the fallback finds the rest."""
    source = RuleOut(FLAT, needs_d_on_c)
    result = plan(FLAT, CHEAP, seed=0, costs=source)
    ran = result.stats["fallback"]
    assert ran["trigger"] == "cycle" and ran["status"] == "solved"
    assert result.solved and result.plan.moves[-2:] == (Move("d", "c"), Move("a", "b"))
    assert_valid(FLAT, result.plan.moves)
    assert _replay_allowed(FLAT, result.plan.moves, needs_d_on_c)
    assert source.committed == list(result.plan.moves)  # the fallback's moves committed too
    assert ran["expanded"] >= 1 and ran["ruled_out"] >= 1 and ran["moves"] >= 2


@pytest.mark.parametrize("seed", [1, 2])
def test_plans_with_the_fallback_validate_and_reach_the_cost_source(seed):
    source = RuleOut(FLAT, needs_d_on_c)
    result = plan(FLAT, CHEAP, seed=seed, costs=source)
    assert result.solved
    assert_valid(FLAT, result.plan.moves)
    assert _replay_allowed(FLAT, result.plan.moves, needs_d_on_c)
    assert source.committed == list(result.plan.moves)


def test_no_plan_within_these_choices_is_its_own_status():
    """a onto b ruled out everywhere: the planner says UNSOLVABLE (not the window budget's
    NO_PLAN) after exhausting the 60 states reachable, from where the windows stopped and from
    init."""
    result = plan(
        FLAT, PlannerConfig(restarts=2, iters=15, max_windows=2), costs=RuleOut(FLAT, never_a_on_b)
    )
    ran = result.stats["fallback"]
    assert result.status is PlanStatus.UNSOLVABLE and ran["status"] == "unsolvable"
    assert "no plan exists within these choices" in ran["reason"]
    assert ran["expanded"] == len(_reachable(FLAT, never_a_on_b))


def test_a_fallback_out_of_budget_says_so():
    """A goal that needs c on e and d on c before a onto b, one window, two expansions: the
    fallback stops at its budget and the result is NO_PLAN with the reason."""
    five = Problem("five", "blocksworld", ("a", "b", "c", "d", "e"), (TABLE,) * 5, (("a", "b"),))

    def rule(state, move):
        return move == Move("a", "b") and not (state[2] == "e" and state[3] == "c")

    config = PlannerConfig(restarts=2, iters=15, max_windows=1, fallback_nodes=2)
    result = plan(five, config, costs=RuleOut(five, rule))
    ran = result.stats["fallback"]
    assert result.status is PlanStatus.NO_PLAN and ran["status"] == "budget"
    assert ran["expanded"] >= 4 and "budget" in ran["reason"]  # A*'s 2, then greedy's 2
    assert "A* stopped after 2 expansions (budget); then greedy" in ran["reason"]
    assert _replay_allowed(five, result.plan.moves, rule)


def test_the_fallback_is_off_without_a_cost_source_and_refused_with_beliefs():
    """Default: only motion-aware planning falls back; fallback=True plans task-only too; with
    beliefs (planning from perception) asking for it is refused in one line."""
    stuck = PlannerConfig(restarts=1, iters=1, max_windows=1)
    problem = random_problem(6, 0)
    assert "fallback" not in plan(problem, stuck).stats
    forced = plan(problem, PlannerConfig(restarts=1, iters=1, max_windows=1, fallback=True))
    assert forced.solved and forced.stats["fallback"]["trigger"] in ("windows", "cycle")
    assert_valid(problem, forced.plan.moves)
    with pytest.raises(TampError, match="cannot run with beliefs"):
        plan(problem, PlannerConfig(fallback=True), beliefs=lambda indices, states: None)


def test_a_star_out_of_budget_hands_over_to_a_greedy_search_from_the_same_state():
    """Eight blocks, no windows' moves, 20 expansions: A* on the lower bound runs out, the
    greedy search on it (helpful moves first) finds a valid plan within as many again."""
    problem = random_problem(8, 3)
    config = PlannerConfig(restarts=1, iters=1, max_windows=1, fallback=True, fallback_nodes=20)
    result = plan(problem, config)
    ran = result.stats["fallback"]
    assert result.solved and ran["status"] == "solved" and not ran["from_start"]
    assert "A* stopped after 20 expansions (budget); then greedy: a plan of" in ran["reason"]
    assert_valid(problem, result.plan.moves)


@dataclass
class Forgetful(RuleOut):
    """`RuleOut` that can drop the moves committed to it (`ArmCosts.forget`)."""

    can_forget = True
    forgot: list = field(default_factory=list)

    def forget(self, index):
        self.forgot.append(index)
        self.committed.clear()


def test_a_fallback_out_of_budget_where_the_windows_left_it_starts_over_from_init():
    """The windows put d on a; one expansion finds nothing from there, but a greedy search
    from the initial state finds a onto b: the plan starts over (``from_start``), the cost
    source forgets the windows' moves and holds only the fallback's."""
    from task.planner.fallback import fall_back

    source = Forgetful(FLAT, lambda state, move: False)
    source.committed.append(Move("d", "a"))  # the windows' move
    wandered = BW.apply_move(FLAT, BW.initial_state(FLAT), Move("d", "a"))
    config = PlannerConfig(fallback=True, fallback_nodes=1)
    found = fall_back(BW, FLAT, wandered, config, costs=source)
    assert found.status is SearchStatus.SOLVED and found.from_start
    assert found.moves == (Move("a", "b"),) and "from the initial state, greedy" in found.reason
    assert source.forgot == [0] and source.committed == [Move("a", "b")]
    plain = RuleOut(FLAT, lambda state, move: False)  # cannot forget: no start over
    kept = fall_back(BW, FLAT, wandered, config, costs=plain)
    assert kept.status is SearchStatus.BUDGET and not kept.from_start


def test_a_restart_probe_takes_a_star_from_the_initial_state_first():
    """The windows put d on a. With ``restart_probe``, A* from the initial state looks first
    and its one-move plan is taken (the cost source forgets the windows' move); without it the
    search starts where the windows left off (d off a, then a onto b)."""
    from task.planner.fallback import fall_back

    wandered = BW.apply_move(FLAT, BW.initial_state(FLAT), Move("d", "a"))
    source = Forgetful(FLAT, lambda state, move: False)
    source.committed.append(Move("d", "a"))  # the windows' move
    config = PlannerConfig(fallback=True, restart_probe=5)
    found = fall_back(BW, FLAT, wandered, config, costs=source)
    assert found.status is SearchStatus.SOLVED and found.from_start
    assert found.moves == (Move("a", "b"),)
    assert "from the initial state, A* within 5 expansions" in found.reason
    assert source.forgot == [0] and source.committed == [Move("a", "b")]
    source = Forgetful(FLAT, lambda state, move: False)
    kept = fall_back(BW, FLAT, wandered, PlannerConfig(fallback=True), costs=source)
    assert kept.status is SearchStatus.SOLVED and not kept.from_start and len(kept.moves) == 2
    with pytest.raises(TampError, match="restart_probe must be >= 0"):
        PlannerConfig(restart_probe=-1)


def test_with_a_deadline_the_start_over_runs_until_it_not_for_the_node_budget():
    """Eight blocks, one block moved off the plan's way, a node budget of one: without a
    deadline every search stops at one expansion; with one, the last search (greedy from the
    initial state) goes on until the deadline and finds a valid plan."""
    from task.planner.fallback import fall_back

    problem = random_problem(8, 3)
    start = BW.initial_state(problem)
    wandered = BW.apply_move(problem, start, BW.legal_moves(problem, start)[0])
    config = PlannerConfig(fallback=True, fallback_nodes=1)
    for deadline in (None, time.perf_counter() + 60):
        source = Forgetful(problem, lambda state, move: False)
        found = fall_back(BW, problem, wandered, config, costs=source, deadline=deadline)
        if deadline is None:
            assert found.status is SearchStatus.BUDGET and not found.from_start
            continue
        assert found.status is SearchStatus.SOLVED and found.from_start and found.expanded > 3
        assert_valid(problem, found.moves)


def test_with_a_deadline_each_search_gets_an_equal_share_of_the_time_left(monkeypatch):
    """A*, then greedy from where the windows left off, then greedy from the initial state:
    with 60 s left, A* may take a third, the greedy search after it half of what is left, the
    start over the rest. Before, under load A* spent the whole deadline from a state the
    start over then had no time to leave (tall variant 18: no plan in 120 s)."""
    import task.planner.fallback as fb

    problem = random_problem(8, 3)
    start = BW.initial_state(problem)
    wandered = BW.apply_move(problem, start, BW.legal_moves(problem, start)[0])
    given = []

    def spy(search, name):
        def run(domain, problem, state, feasible, nodes, deadline):
            given.append((name, state == start, deadline - time.perf_counter()))
            # the first two stand for searches that run out of their budget at once
            return search(
                domain, problem, state, feasible, 1 if len(given) < 3 else nodes, deadline
            )

        return run

    monkeypatch.setattr(fb, "lazy_best_first", spy(fb.lazy_best_first, "A*"))
    monkeypatch.setattr(fb, "lazy_greedy", spy(fb.lazy_greedy, "greedy"))
    source = Forgetful(problem, lambda state, move: False)
    config = PlannerConfig(fallback=True, fallback_nodes=50)
    found = fb.fall_back(
        BW, problem, wandered, config, costs=source, deadline=time.perf_counter() + 60
    )
    assert [(name, at_start) for name, at_start, _ in given] == [
        ("A*", False),
        ("greedy", False),
        ("greedy", True),
    ]
    left = [t for _, _, t in given]
    assert left[0] == pytest.approx(20, abs=0.5) and left[1] == pytest.approx(30, abs=0.5)
    assert left[2] == pytest.approx(60, abs=0.5)
    assert found.status is SearchStatus.SOLVED and found.from_start
    assert_valid(problem, found.moves)


def test_a_run_of_one_blocks_moves_is_merged_where_the_merged_move_is_allowed():
    """a to the table then onto c is one move, a onto c, unless that move is ruled out where
    the run began; a run that comes back where it began is cut; other moves stay as they
    were and the plan still reaches the goal."""
    from task.symbolic.shorten import merge_runs

    problem = Problem(
        "run",
        "blocksworld",
        ("a", "b", "c", "d"),
        ("b", TABLE, TABLE, TABLE),
        (("a", "c"), ("d", "b")),
    )
    start = BW.initial_state(problem)
    moves = (Move("a", TABLE), Move("a", "c"), Move("d", "a"), Move("d", TABLE), Move("d", "b"))
    assert merge_runs(BW, problem, start, moves) == (Move("a", "c"), Move("d", "b"))
    never = lambda state, move: move != Move("a", "c") or state != start  # noqa: E731
    kept = merge_runs(BW, problem, start, moves, never)
    assert kept == (Move("a", TABLE), Move("a", "c"), Move("d", "b"))
    assert_valid(problem, kept)
    back = (Move("c", "d"), Move("c", TABLE), Move("a", "c"), Move("d", "b"))
    assert merge_runs(BW, problem, start, back) == back[2:]
