"""The differentiable rollout, the optimiser, decoding and the replanning planner."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import pytest
import torch

from task.config import MAX_HORIZON, PlannerConfig
from task.decode import DecodeRule, WindowStart, decode_row
from task.domains import get_domain
from task.errors import ProblemError, TampError
from task.planner import plan, plan_batch
from task.problem import PlanStatus, Problem
from task.rollout import rollout
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_moves
from tests.pddl_check import assert_valid, validate_moves

BW = get_domain("blocksworld")
FAST = PlannerConfig(restarts=4, iters=60)


def _batch(problems, dtype=torch.float64):
    return BW.encode(problems, [BW.initial_state(p) for p in problems], dtype)


@pytest.mark.parametrize("goal_loss", ["atoms", "towers"])
def test_rollout_gradcheck_float64(goal_loss):
    problem = random_problem(3, 0)
    batch = _batch([problem])
    steps = torch.ones(1, 2, dtype=torch.bool)
    config = replace(PlannerConfig(horizon=2), goal_loss=goal_loss)
    gen = torch.Generator().manual_seed(0)
    logits = torch.randn((1, 2, *batch.action_mask.shape[1:]), generator=gen, dtype=torch.float64)
    logits.requires_grad_(True)

    def f(a):
        return rollout(BW, a, batch, steps, config).loss

    assert torch.autograd.gradcheck(f, (logits,), eps=1e-6, atol=1e-5)


def test_rows_of_a_batch_are_independent():
    problems = [random_problem(3, 0), random_problem(5, 1)]
    batch = _batch(problems)
    steps = torch.ones(2, 3, dtype=torch.bool)
    logits = torch.randn((2, 3, *batch.action_mask.shape[1:]), dtype=torch.float64)
    logits.requires_grad_(True)
    rollout(BW, logits, batch, steps, PlannerConfig()).loss[0].backward()
    assert logits.grad[1].abs().sum() == 0.0
    assert logits.grad[0].abs().sum() > 0.0


@pytest.mark.parametrize("goal_loss", ["atoms", "towers"])
def test_padded_problem_rolls_out_like_the_unpadded_one(goal_loss):
    small, big = random_problem(3, 2), random_problem(6, 3)
    steps = torch.ones(1, 3, dtype=torch.bool)
    alone = _batch([small])
    padded = _batch([small, big])
    gen = torch.Generator().manual_seed(1)
    a = torch.randn((1, 3, *alone.action_mask.shape[1:]), generator=gen, dtype=torch.float64)
    # embed the small problem's logits into the padded layout: entity slots, table, STAY
    n_big = padded.n
    a_pad = torch.zeros((1, 3, n_big, n_big + 2), dtype=torch.float64)
    a_pad[:, :, :3, :3] = a[:, :, :, :3]
    a_pad[:, :, :3, n_big:] = a[:, :, :, 3:]
    config = PlannerConfig(goal_loss=goal_loss)
    one = rollout(BW, a, alone, steps, config)
    sub = type(padded)(*(t[:1] for t in padded.astuple()))
    two = rollout(BW, a_pad, sub, steps, config)
    assert torch.allclose(one.loss, two.loss)


def test_decoding_stops_at_the_first_illegal_move():
    problem = Problem("p", "blocksworld", ("a", "b"), ("table", "a"), (("a", "b"),))
    state = BW.initial_state(problem)  # b on a
    gates = torch.zeros(2, 2, 3)
    gates[0, 0, 1] = 0.9  # a -> b, illegal: a is covered
    gates[1, 1, 2] = 0.9  # b -> table, legal but after an illegal step
    win = decode_row(BW, WindowStart(problem, state), gates, 0.0, DecodeRule(0.3))
    assert win.moves == () and not win.complete
    gates[0] = 0.0
    gates[0, 1, 2] = 0.2  # below the threshold: a STAY step
    win = decode_row(BW, WindowStart(problem, state), gates, 0.0, DecodeRule(0.3))
    assert [str(m) for m in win.moves] == ["move(b -> table)"]


@pytest.mark.parametrize("seed", range(4))
def test_small_problems_solved_with_legal_plans(seed):
    problem = random_problem(3 + seed % 2, seed)
    result = plan(problem, FAST, seed=seed)
    assert result.solved and result.plan  # random_problem never starts at its goal
    assert_valid(problem, result.plan)  # the PDDL validator, not the decoder's own checks


def test_batched_and_sequential_paths_both_solve():
    problems = [random_problem(4, s) for s in range(3)]
    for batched in (True, False):
        results = plan_batch(problems, replace(FAST, batched=batched), seed=0)
        assert [r.solved for r in results] == [True] * 3
        for problem, result in zip(problems, results, strict=True):
            assert_valid(problem, result.plan)


def test_paper_configuration_plans_a_three_move_problem():
    # a on b; goal a on b on c: a must leave b, b go onto c, a come back (two goal atoms, 3 moves)
    problem = Problem(
        "p", "blocksworld", ("a", "b", "c"), ("b", "table", "table"), (("b", "c"), ("a", "b"))
    )
    config = PlannerConfig(goal_loss="atoms", lookahead_share=0.0, restarts=1)
    result = plan(problem, config)
    assert len(optimal_moves(problem)) == 3
    assert result.solved and len(result.plan) == 3
    assert_valid(problem, result.plan)


def test_goal_already_true_gives_an_empty_plan():
    problem = Problem("p", "blocksworld", ("a", "b"), ("b", "table"), (("a", "b"),))
    result = plan(problem, FAST)
    assert result.solved and len(result.plan) == 0
    assert validate_moves(problem, result.plan).valid


def test_bad_inputs_raise_one_line_errors():
    with pytest.raises(TampError, match="horizon"):
        PlannerConfig(horizon=0)
    with pytest.raises(TampError, match="threshold"):
        PlannerConfig(threshold=1.5)
    with pytest.raises(ProblemError, match="unknown domain 'sokobanx'"):
        get_domain("sokobanx")
    with pytest.raises(ProblemError, match="goal loss"):
        plan(random_problem(3, 0), replace(FAST, goal_loss="bogus"))


def test_temperature_anneals_geometrically_from_tau_to_tau_end():
    from task.optimize import temperature

    config = PlannerConfig(tau=0.5, tau_end=0.05, iters=11)
    taus = [temperature(config, k) for k in range(11)]
    assert taus[0] == pytest.approx(0.5) and taus[-1] == pytest.approx(0.05)
    assert all(a > b for a, b in itertools.pairwise(taus))
    assert temperature(replace(config, tau_end=0.5), 7) == pytest.approx(0.5)


def test_restart_ranking_prefers_goal_then_estimated_total():
    from task.decode import DecodedWindow
    from task.problem import Move

    m = Move("a", "table")
    reached_long = DecodedWindow((m, m, m), (), True, True, 9.0, 0)
    reached_short = DecodedWindow((m,), (), True, True, 9.0, 0)
    stuck = DecodedWindow((), (), False, True, 0.0, 3)
    detour = DecodedWindow((m, m), (), False, True, 0.0, 3)  # 2 moves, still 3 to go
    progress = DecodedWindow((m, m), (), False, True, 5.0, 1)  # 2 moves, 1 to go
    ranked = sorted([stuck, detour, progress, reached_long, reached_short], key=DecodedWindow.key)
    assert ranked == [reached_short, reached_long, progress, detour, stuck]


def test_restart_ranking_reads_a_domain_estimate_but_dead_ends_stay_last():
    from task.decode import DecodedWindow
    from task.problem import Move

    m = Move("a", "table")
    # by the lower bound alone the short window wins; the estimate says the long one is ahead
    short = DecodedWindow((m,), (), False, True, 0.0, 2, estimated=9.0)
    long = DecodedWindow((m, m, m), (), False, True, 0.0, 2, estimated=4.0)
    dead = DecodedWindow((m, m, m), (), False, True, 0.0, math.inf, estimated=0.0)
    assert sorted([dead, short, long], key=DecodedWindow.key) == [long, short, dead]
    no_estimate = [replace(w, estimated=None) for w in (short, long)]
    assert min(no_estimate, key=DecodedWindow.key).moves == (m,)


def test_a_window_back_to_a_visited_state_ranks_below_progress_elsewhere():
    from task.decode import decode_best

    problem = random_problem(4, 3)
    state = BW.initial_state(problem)
    ahead = optimal_moves(problem)[0]
    after = BW.apply_move(problem, state, ahead)
    n, y = problem.n, problem.n + len(problem.fixed)
    gates = torch.zeros(2, 1, n, y)  # restart 0: the optimal first move; restart 1: a STAY
    gates[0, 0, problem.entities.index(ahead.entity), problem.index(ahead.target)] = 1
    losses = torch.tensor([5.0, 0.0])
    rule = DecodeRule(0.3, 2)
    best = decode_best(BW, [WindowStart(problem, state)], gates, losses, rule)[0]
    assert best.moves == (ahead,) and not best.revisit
    best = decode_best(BW, [WindowStart(problem, state, {after})], gates, losses, rule)[0]
    assert best.moves == () and not best.revisit  # staying beats going back to ``after``
    best = decode_best(BW, [WindowStart(problem, state, {state, after})], gates, losses, rule)[0]
    assert best.moves == (ahead,) and best.revisit  # both loop: then progress ranks first


def test_domain_planner_defaults_and_overrides():
    blocks = PlannerConfig.for_domain("blocksworld")
    parts = (("horizon", 5), ("lookahead", 8), ("restarts", 8), ("iters", 20))
    assert blocks == PlannerConfig(
        park_from=30, safe_from=16, improve_s=30.0, improve_up_to=15, part_window=parts
    )
    assert not blocks.takes_safe(random_problem(15, 0)) and blocks.takes_safe(random_problem(16, 0))
    assert not blocks.parks(random_problem(29, 0)) and blocks.parks(random_problem(30, 0))
    assert not PlannerConfig().parks(random_problem(50, 0))  # other domains: asked for only
    assert PlannerConfig(park_free=True).parks(random_problem(3, 0))
    with pytest.raises(TampError, match="park_from"):
        PlannerConfig(park_from=0)
    sokoban = PlannerConfig.for_domain("sokoban")
    assert (sokoban.lookahead, sokoban.max_windows) == (8, 100)
    assert PlannerConfig.for_domain("sokoban", max_windows=7, horizon=2).max_windows == 7
    with pytest.raises(ProblemError, match="unknown domain"):
        PlannerConfig.for_domain("chess")


def test_lower_bound_is_zero_at_the_goal_and_admissible():
    for seed in range(5):
        problem = random_problem(5, seed)
        state = BW.initial_state(problem)
        optimum = optimal_moves(problem)
        assert BW.lower_bound(problem, state) <= len(optimum)
        for move in optimum:
            state = BW.apply_move(problem, state, move)
        assert BW.lower_bound(problem, state) == 0


def test_deep_unstacking_needs_more_moves_than_the_lookahead():
    # tower c-a-d-b; c must end on b: six moves, beyond the 5-move lookahead (PlanBench 330)
    problem = Problem(
        "deep",
        "blocksworld",
        ("a", "b", "c", "d"),
        ("c", "d", "table", "a"),
        (("b", "d"), ("c", "b"), ("d", "a")),
    )
    result = plan(problem, PlannerConfig(), seed=0)
    optimum = len(optimal_moves(problem))
    assert optimum == 6
    assert result.solved and result.stats["windows"] >= 2  # no single window covers 6 moves
    assert_valid(problem, result.plan)
    # Not the exact optimum: windows are planned greedily, so a seed can take a detour. Over
    # seeds 0-9 the planner found 6 moves eight times, 8 (seed 1) and 10 (seed 9); seed 0 finds 6.
    # One two-move detour is tolerated so a harmless numerical change does not flip the test.
    assert optimum <= len(result.plan) <= optimum + 2


def test_a_time_limit_stops_the_planner_and_says_how_far_it_got():
    problem = random_problem(6, 11)
    slow = PlannerConfig(time_limit_s=1e-9)  # over before the first window
    result = plan(problem, slow, seed=0)
    assert not result.solved and result.stats["windows"] == 0
    assert (
        "time limit" in result.stats["time_limit"]
        and "more moves needed" in result.stats["time_limit"]
    )
    assert "time_limit" not in plan(problem, PlannerConfig(time_limit_s=600), seed=0).stats
    with pytest.raises(TampError, match="time_limit_s must be > 0"):
        PlannerConfig(time_limit_s=0)


@pytest.mark.parametrize(
    "long", [{"iters": 5000}, {"horizon": MAX_HORIZON, "lookahead": MAX_HORIZON}]
)
def test_the_time_limit_holds_inside_a_window(long):
    """A first window far longer than the limit (5000 Adam steps, or 1000-step rollouts) is
    cut at the limit and abandoned: no move of it is kept and the result says why. The early
    stop of a proven window is off (``proof_every=0``): on a quiet machine it proved this
    problem's first window within the limit, and the window never reached the cut."""
    problem = random_problem(6, 11)
    result = plan(problem, PlannerConfig(time_limit_s=0.5, proof_every=0, **long), seed=0)
    assert result.status is PlanStatus.NO_PLAN and result.plan.moves == ()
    assert result.stats["windows"] == 0
    assert result.stats["time_limit"].startswith("stopped at the 0.5 s time limit after 0 windows")


def test_a_window_longer_than_the_bound_is_refused():
    for name in ("horizon", "lookahead"):
        with pytest.raises(TampError, match=f"{name} must be in 1..{MAX_HORIZON}"):
            PlannerConfig(**{name: MAX_HORIZON + 1})


def test_the_planners_adam_is_torch_adam_step_for_step():
    from task.optimize import Adam

    gen = torch.Generator().manual_seed(0)
    x0 = torch.randn(4, 3, generator=gen)
    y0 = torch.randn(5, generator=gen)
    ours = [x0.clone().requires_grad_(True), y0.clone().requires_grad_(True)]
    ref = [x0.clone().requires_grad_(True), y0.clone().requires_grad_(True)]
    opt = Adam([{"params": [ours[0]], "lr": 0.1}, {"params": [ours[1]], "lr": 1e-3}])
    ref_opt = torch.optim.Adam([{"params": [ref[0]], "lr": 0.1}, {"params": [ref[1]], "lr": 1e-3}])
    for k in range(30):
        for params, o in ((ours, opt), (ref, ref_opt)):
            o.zero_grad()
            loss = (params[0].sin() * (k + 1)).sum() + (params[1] ** 3).sum()
            if k % 4 == 3:  # a step where one parameter has no gradient
                loss = (params[0] ** 2).sum()
            loss.backward()
            o.step()
        assert torch.equal(ours[0], ref[0]) and torch.equal(ours[1], ref[1]), k


def _adam_steps(monkeypatch) -> list:
    from task import optimize

    steps, step = [], optimize.Adam.step
    monkeypatch.setattr(optimize.Adam, "step", lambda self: (steps.append(1), step(self))[1])
    return steps


@pytest.mark.parametrize("seed", range(3))
def test_a_window_stops_once_it_reaches_the_goal_in_as_few_moves_as_the_bound(seed, monkeypatch):
    """`PlannerConfig.proof_every`: a window whose decode reaches the goal in as many moves as
    the lower bound from its start stops early; no plan is longer than without the stop."""
    problem = random_problem(4, seed)
    steps = _adam_steps(monkeypatch)
    config = replace(FAST, iters=30)
    full = plan(problem, replace(config, proof_every=0), seed=seed)
    all_steps = len(steps)
    steps.clear()
    early = plan(problem, config, seed=seed)
    assert len(steps) <= all_steps
    assert full.solved and early.solved
    validate_moves(problem, early.plan.moves)
    assert len(early.plan) <= len(full.plan)


def test_windows_of_many_problems_are_not_read_early(monkeypatch):
    problems = [random_problem(3, 0), random_problem(3, 1)]
    steps = _adam_steps(monkeypatch)
    results = plan_batch(problems, replace(FAST, iters=10, proof_every=2))
    assert all(r.solved for r in results)
    assert len(steps) == 10 * max(r.stats["windows"] for r in results)


def test_a_window_reaching_the_goal_in_the_bound_stops_at_the_first_read(monkeypatch):
    problem = Problem("one-move", "blocksworld", ("a", "b"), ("table", "table"), (("a", "b"),))
    steps = _adam_steps(monkeypatch)
    result = plan(problem, replace(FAST, proof_every=3))
    assert [str(m) for m in result.plan.moves] == ["move(a -> b)"]
    assert len(steps) == 3
    with pytest.raises(TampError, match="proof_every must be >= 0"):
        PlannerConfig(proof_every=-1)


def _flat_costs(problem, banned=()):
    """Every move priced 1.0, ``banned`` (entity, target) pairs IMPOSSIBLE."""
    from task.costs import IMPOSSIBLE
    from tests.task.test_costs import FixedCosts

    c = torch.ones(1, problem.n, len(problem.targets), dtype=torch.float64)
    for x, y in banned:
        c[:, problem.entities.index(x), problem.index(y)] = IMPOSSIBLE
    return FixedCosts(c)


def test_with_move_costs_a_window_stops_early_only_with_proof_costs_and_never_on_a_refused_move(
    monkeypatch,
):
    """`PlannerConfig.proof_costs`: with move costs a window is read early only when asked;
    the early read refuses a move the costs rule out as the final decode does."""
    problem = Problem("one-move", "blocksworld", ("a", "b"), ("table", "table"), (("a", "b"),))
    costs = _flat_costs(problem)
    config = replace(FAST, proof_every=3, lambda_motion=0.05)
    steps = _adam_steps(monkeypatch)
    plan(problem, config, costs=costs)
    assert len(steps) == config.iters  # costs without proof_costs: every step
    steps.clear()
    early = plan(problem, replace(config, proof_costs=True), costs=costs)
    assert [str(m) for m in early.plan.moves] == ["move(a -> b)"] and len(steps) == 3
    banned = _flat_costs(problem, {("a", "b")})
    refused = plan(problem, replace(config, proof_costs=True, max_windows=2), costs=banned)
    assert "move(a -> b)" not in [str(m) for m in refused.plan.moves]


@pytest.mark.parametrize("name", ["tau_end", "lr", "tau", "decode_tau", "threshold", "improve_s"])
@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_a_non_finite_float_setting_is_refused(name, bad):
    """tau_end=nan planned for a minute and reported 'no plan': nan passes every comparison."""
    with pytest.raises(TampError, match=f"PlannerConfig.{name} must be a finite number, got"):
        PlannerConfig(**{name: bad})
    with pytest.raises(TampError, match="time_limit_s must be a finite number"):
        PlannerConfig(time_limit_s=float("nan"))
