"""The generic STRIPS lift: soft step == crisp STRIPS apply, [0, 1] values, gradients,
planning end to end, the crisp bound, and the one-line errors on what it does not support."""

from __future__ import annotations

import dataclasses
import functools
import math
import random
from collections import deque
from pathlib import Path

import pytest
import torch

from task.config import PlannerConfig
from task.domains import get_domain, strips_soft
from task.domains.base import INF
from task.domains.strips import GRIPPER, problem_from_text
from task.errors import PDDLError, ProblemError
from task.planner import plan
from task.problem import Action
from task.rollout import rollout
from task.symbolic import relaxed, strips
from task.symbolic.validate import validate

LIFT = get_domain("strips")
IPC = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "ipc"

TOY = """(define (domain toy) (:requirements :strips {req})
  (:predicates (p) (q ?x) (r) (fuel)) {extra}
  (:action a :parameters (?x) :precondition {pre} :effect {eff})
  (:action waste :parameters () :precondition (fuel) :effect (not (fuel))))"""
TOY_PROBLEM = (
    "(define (problem toy1) (:domain toy) (:objects o1 o2) (:init (p) {init}) (:goal {goal}))"
)


@functools.cache
def _samples(seed: int) -> tuple:
    return tuple(LIFT.samples(seed))


def _sample(seed: int, k: int):
    """The k-th sample problem: 0-2 blocksworld of 3-5 blocks, 3-4 gripper of 2-3 balls."""
    return _samples(seed)[k]


def _toy(goal="(q o1)", req="", extra="", pre="(p)", eff="(q ?x)", init=""):
    domain = TOY.format(req=req, extra=extra, pre=pre, eff=eff)
    return problem_from_text(domain, TOY_PROBLEM.format(init=init, goal=goal), "toy")


LINE = """(define (domain line) (:requirements :strips)
  (:predicates (at ?x) (link ?x ?y))
  (:action go :parameters (?x ?y) :precondition (and (at ?x) (link ?x ?y))
    :effect (and (at ?y) (not (at ?x)))))"""
LINE_PROBLEM = """(define (problem line4) (:domain line) (:objects l0 l1 l2 l3)
  (:init (at l0) (link l0 l1) (link l1 l0) (link l1 l2) (link l2 l1) (link l2 l3) (link l3 l2))
  (:goal (at l3)))"""


def _walks(seed: int = 0, length: int = 6):
    """(problem, state) along seeded random legal walks from every sample problem."""
    rng = random.Random(seed)
    for problem in _samples(seed):
        state = LIFT.initial_state(problem)
        yield problem, state
        for _ in range(length):
            state = LIFT.apply_move(problem, state, rng.choice(LIFT.legal_moves(problem, state)))
            yield problem, state


def _onehot(batch, j: int) -> torch.Tensor:
    M = torch.zeros(batch.action_mask.shape, dtype=torch.float64)  # (1, 1, G + 1)
    M[0, 0, j] = 1.0
    return M


def test_step_equals_crisp_strips_apply_on_onehot_states():
    checked = {"legal": 0, "illegal": 0}
    for problem, state in _walks():
        batch = LIFT.encode([problem], [state], torch.float64)
        atoms = LIFT.to_atoms(problem, state)
        for j, action in enumerate(problem.data.actions):
            F1, g = LIFT.step(batch.F0, _onehot(batch, j), batch)
            ground = strips.ground(problem.data.pddl_domain, problem.data.pddl_problem, action)
            if strips.applicable(atoms, ground):
                assert LIFT.check_move(problem, state, action) is None
                after = strips.apply(atoms, ground)  # the crisp oracle, statics included
                assert LIFT.to_atoms(problem, LIFT.apply_move(problem, state, action)) == after
                expected = LIFT.encode([problem], [after], torch.float64).F0
                assert torch.equal(F1, expected), action
                assert g.sum().item() == 1.0
                checked["legal"] += 1
            else:
                assert LIFT.check_move(problem, state, action) is not None
                assert g.abs().sum().item() == 0.0, f"inapplicable {action} carries mass"
                assert torch.equal(F1, batch.F0)
                checked["illegal"] += 1
        assert torch.equal(LIFT.consistency(batch.F0, batch), batch.F0)
    assert min(checked.values()) >= 100, checked


def test_padding_never_applies_nor_decodes():
    small, big = _sample(1, 0), _sample(1, 2)
    batch = LIFT.encode([small, big], [small.data.init, big.data.init], torch.float64)
    g_small = len(small.data.actions)
    assert not batch.action_mask[0, 0, g_small:-1].any() and batch.action_mask[0, 0, -1]
    M = torch.zeros(2, 1, batch.action_mask.shape[-1], dtype=torch.float64)
    M[0, 0, g_small:-1] = 1.0 / (M.shape[-1] - 1 - g_small)  # unmasked padding columns
    M[1, 0, -1] = 1.0
    F1, g = LIFT.step(batch.F0, M, batch)
    assert g.abs().sum() == 0.0 and torch.equal(F1, batch.F0)
    assert LIFT.decode(small, 0, g_small, 1) is None and LIFT.decode(small, 0, 0, 1) is not None
    p_small = len(small.data.atoms)
    assert batch.F0[0, 0, p_small:].abs().sum() == 0.0 and batch.goal[0, 0, p_small:].sum() == 0


def test_values_stay_in_unit_interval_under_soft_actions():
    gen = torch.Generator().manual_seed(0)
    for problem, state in _walks(length=2):
        batch = LIFT.encode([problem], [state], torch.float64)
        F = torch.rand(batch.F0.shape, generator=gen, dtype=torch.float64)
        for _ in range(4):
            logits = torch.randn(batch.action_mask.shape, generator=gen, dtype=torch.float64)
            M = torch.softmax(logits.masked_fill(~batch.action_mask, -1e9), -1)
            F, g = LIFT.step(F, M, batch)
            assert (F >= 0).all() and (F <= 1).all() and (g >= 0).all()
            assert g.sum() <= 1.0 + 1e-12
            F = LIFT.consistency(F, batch)


@pytest.mark.parametrize("goal_loss", ["ff", "hadd", "atoms"])
def test_rollout_gradcheck_float64(goal_loss):
    problem = _sample(0, 3)  # a tiny gripper
    batch = LIFT.encode([problem], [problem.data.init], torch.float64)
    gen = torch.Generator().manual_seed(0)
    soft = 0.1 + 0.8 * torch.rand(batch.F0.shape, generator=gen, dtype=torch.float64)
    batch = dataclasses.replace(batch, F0=soft)
    steps = torch.ones(1, 2, dtype=torch.bool)
    config = PlannerConfig(horizon=2, goal_loss=goal_loss)
    shape = (1, 2, *batch.action_mask.shape[1:])
    logits = torch.randn(shape, generator=gen, dtype=torch.float64).requires_grad_(True)

    def f(a):
        return rollout(LIFT, a, batch, steps, config).loss

    assert torch.autograd.gradcheck(f, (logits,), eps=1e-6, atol=1e-5)


def test_relaxed_cost_is_h_add_and_rewards_a_partial_first_step():
    """One-hot: the soft h_add of (at l3) is the crisp 3. Half a step l0 -> l1 earns half the
    full step's gain (the consumed (at l0) is not charged against the (at l1) it became)."""
    line = problem_from_text(LINE, LINE_PROBLEM, "line")
    batch = LIFT.encode([line], [line.data.init], torch.float64)
    batch.static["prior"] = torch.ones_like(batch.static["prior"])  # M is the applied mass
    go = line.data.index[Action("go", ("l0", "l1"))]

    def cost(eps: float) -> float:
        M = torch.zeros(batch.action_mask.shape, dtype=torch.float64)
        M[0, 0, go], M[0, 0, -1] = eps, 1.0 - eps
        F, _ = LIFT.step(batch.F0, M, batch)
        return (batch.goal[:, 0] * strips_soft.relaxed_cost(F, batch)).sum().item()

    assert cost(0.0) == pytest.approx(3.0, abs=0.1)
    assert cost(1.0) == pytest.approx(2.0, abs=0.1)
    assert cost(0.5) == pytest.approx((cost(0.0) + cost(1.0)) / 2, abs=1e-3)
    assert cost(0.01) < cost(0.0)


def _optimal_length(problem) -> int:
    """Breadth-first search over crisp states (small problems only)."""
    start = LIFT.initial_state(problem)
    seen, queue = {start: 0}, deque([start])
    while queue:
        state = queue.popleft()
        if LIFT.is_goal(problem, state):
            return seen[state]
        for move in LIFT.legal_moves(problem, state):
            nxt = LIFT.apply_move(problem, state, move)
            if nxt not in seen:
                seen[nxt] = seen[state] + 1
                queue.append(nxt)
    return INF


def test_lower_bound_is_admissible_and_finds_dead_ends():
    for problem in _samples(2):
        assert 0 < LIFT.lower_bound(problem, problem.data.init) <= _optimal_length(problem)
    toy = _toy(goal="(q o1)", pre="(fuel)", init="(fuel)")
    assert LIFT.lower_bound(toy, toy.data.init) == 1
    dead = LIFT.apply_move(toy, toy.data.init, Action("waste"))
    assert LIFT.lower_bound(toy, dead) == INF


def test_ff_estimate_is_a_relaxed_plan_at_least_lm_cut():
    for problem, state in _walks(3):
        bound, estimate = LIFT.lower_bound(problem, state), LIFT.estimate(problem, state)
        assert bound <= estimate < INF
        assert (estimate == 0) == LIFT.is_goal(problem, state)
    line = problem_from_text(LINE, LINE_PROBLEM, "line")
    assert LIFT.estimate(line, line.data.init) == 3  # the relaxed plan is the real one here
    toy = _toy(goal="(q o1)", pre="(fuel)", init="(fuel)")
    dead = LIFT.apply_move(toy, toy.data.init, Action("waste"))
    assert LIFT.estimate(toy, dead) == INF


@pytest.mark.parametrize("goal_loss", ["ff", "hadd", "atoms"])
def test_plans_a_tiny_gripper_end_to_end(goal_loss):
    problem = _sample(3, 3)
    result = plan(problem, PlannerConfig(restarts=4, goal_loss=goal_loss), seed=0)
    assert result.solved
    actions = LIFT.to_actions(problem, result.plan.moves)
    check = validate(problem.data.pddl_domain, problem.data.pddl_problem, actions)
    assert check.valid, check.reason


def test_pddl_round_trip_and_atoms():
    problem = _sample(0, 0)
    again = problem_from_text(LIFT.pddl_domain_text(problem), LIFT.to_pddl(problem), "again")
    assert again.data.actions == problem.data.actions and again.data.init == problem.data.init
    assert LIFT.to_atoms(problem, problem.data.init) == strips.initial_state(
        problem.data.pddl_problem
    )
    with pytest.raises(ProblemError, match="no domain file of its own"):
        LIFT.pddl_domain_text()
    assert LIFT.matches(problem.data.pddl_domain)


def test_moves_outside_the_grounding():
    problem = _sample(0, 0)
    state = problem.data.init
    with pytest.raises(ProblemError, match="unknown action"):
        LIFT.check_move(problem, state, Action("fly", ("a",)))
    with pytest.raises(ProblemError, match="unknown object"):
        LIFT.check_move(problem, state, Action("pick-up", ("zz",)))
    toy = _toy(goal="(p)", pre="(and (p) (r))")  # (r) never holds: (a o1) is not grounded
    never = Action("a", ("o1",))
    assert never not in toy.data.actions
    assert "no state reachable" in LIFT.check_move(toy, toy.data.init, never)
    with pytest.raises(ProblemError, match="illegal"):
        LIFT.apply_move(toy, toy.data.init, never)
    unstack = Action("unstack", ("a", "b"))
    assert LIFT.check_move(problem, state, unstack) == "precondition (on a b) does not hold"
    with pytest.raises(ProblemError, match="illegal"):
        LIFT.to_actions(problem, [unstack])
    assert LIFT.to_actions(problem, [unstack], strict=False) == (unstack,)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (dict(req=":negative-preconditions", pre="(and (p) (not (q ?x)))"), "negative"),
        (dict(req=":conditional-effects", eff="(when (p) (q ?x))"), "conditional effect"),
        (dict(req=":conditional-effects", eff="(forall (?y) (q ?y))"), "universal effect"),
        (
            dict(req=":numeric-fluents", extra="(:functions (c))", eff="(increase (c) 1)"),
            "numeric fluent",
        ),
        (dict(req=":derived-predicates", extra="(:derived (r) (p))"), "derived predicate"),
        (dict(goal="(not (p))"), "goal literal"),
    ],
)
def test_unsupported_features_are_one_line_pddl_errors(kwargs, message):
    with pytest.raises(PDDLError, match=message) as info:
        _toy(**kwargs)
    assert "\n" not in str(info.value)


def test_unreachable_goal_is_a_problem_error():
    with pytest.raises(ProblemError, match=r"goal \(r\) is unreachable") as info:
        _toy(goal="(and (q o1) (r))")
    assert "\n" not in str(info.value)


@pytest.mark.shared
def test_ipc_gripper_task01_is_planned_and_valid():
    """Reads ../shared/data/ipc (skips cleanly without it)."""
    if not (IPC / "gripper" / "task01.pddl").is_file():
        pytest.skip(f"IPC data not found at {IPC} (needs the ../shared checkout)")
    from task.symbolic import pddl_io

    domain = pddl_io.load_domain(IPC / "gripper" / "domain.pddl")
    text = pddl_io.read_text(IPC / "gripper" / "task01.pddl")
    problem = LIFT.from_pddl(domain, pddl_io.parse_problem(text, domain=domain), ())
    assert problem.data.static  # (room rooma), (ball ball1), ... are dropped from the tensors
    result = plan(problem, PlannerConfig(), seed=0)
    check = validate(domain, problem.data.pddl_problem, LIFT.to_actions(problem, result.plan))
    assert result.solved and check.valid, check.reason


def test_relaxed_cost_is_crisp_h_add_on_ties():
    """One-hot states of the sample walks: the soft h_add of the goal is the crisp h_add, also
    where an atom has several equally cheap achievers (a ball either gripper may pick), which
    a log-sum-exp softmin put tau log k below."""
    for problem, state in _walks(3):
        batch = LIFT.encode([problem], [state], torch.float64)
        soft = (batch.goal[:, 0] * strips_soft.relaxed_cost(batch.F0, batch)).sum().item()
        h, _ = relaxed.hadd(problem.data, state)
        crisp = sum(h[problem.data.column[a]] for a in problem.data.goal)
        assert soft == pytest.approx(crisp, abs=1e-2), problem.name


def test_relaxed_plan_size_is_h_ff_on_onehot_states():
    """The soft relaxed plan on one-hot states: h_FF exactly without ties (a line, gripper
    after its first pick), between h_FF - 1 and h_add with them (ties split the plan)."""
    line = problem_from_text(LINE, LINE_PROBLEM, "line")
    batch = LIFT.encode([line], [line.data.init], torch.float64)
    assert strips_soft.relaxed_plan_size(batch.F0, batch).item() == pytest.approx(3.0, abs=1e-3)
    for problem, state in _walks(3):
        batch = LIFT.encode([problem], [state], torch.float64)
        soft = strips_soft.relaxed_plan_size(batch.F0, batch).item()
        ff = relaxed.ff(problem.data, state)
        h, _ = relaxed.hadd(problem.data, state)
        crisp_add = sum(h[problem.data.column[a]] for a in problem.data.goal)
        assert ff - 1.0 <= soft <= crisp_add + 1e-3, problem.name


THREE_BALLS = """(define (problem three) (:domain tiny-gripper)
  (:objects rooma roomb - room left right - gripper ball1 ball2 ball3 - ball)
  (:init (at-robby rooma) (free left) (free right) (at ball1 rooma) (at ball2 rooma)
         (at ball3 rooma))
  (:goal (and (at ball1 roomb) (at ball2 roomb) (at ball3 roomb))))"""


def test_ff_goal_term_counts_a_shared_precondition_once():
    """Gripper, three balls to carry: the move to the other room serves every drop, and the
    soft relaxed plan counts it once, as h_FF does (7, then 6 after each pick), where h_add
    counts it per ball (9, then 8). The "ff" goal term falls with the first pick."""
    problem = problem_from_text(GRIPPER, THREE_BALLS, "three")
    start = problem.data.init
    one = LIFT.apply_move(problem, start, Action("pick", ("ball1", "rooma", "left")))
    two = LIFT.apply_move(problem, one, Action("pick", ("ball2", "rooma", "right")))
    states = [start, one, two]
    batch = LIFT.encode([problem] * 3, states, torch.float64)
    size = strips_soft.relaxed_plan_size(batch.F0, batch).tolist()
    assert size == pytest.approx([relaxed.ff(problem.data, s) for s in states], abs=2e-2)
    assert size == pytest.approx([7.0, 6.0, 6.0], abs=2e-2)
    hadd = (batch.goal[:, 0] * strips_soft.relaxed_cost(batch.F0, batch)).sum(-1)
    assert hadd.tolist() == pytest.approx([9.0, 8.0, 8.0], abs=1e-2)
    ff = LIFT.goal_loss(batch.F0, batch, "ff")
    assert ff[1] < ff[0]


def test_prior_favours_the_relaxed_plan_and_keeps_onehot_steps_exact():
    problem = _sample(3, 4)
    state = problem.data.init
    batch = LIFT.encode([problem], [state], torch.float64)
    prior = batch.static["prior"][0]  # (G + 1,)
    chosen = set(relaxed.relaxed_plan(problem.data, state))
    helpful = set(relaxed.helpful(problem.data, state))
    for j in range(len(problem.data.actions)):
        bonus = (j in chosen) * strips_soft.PRIOR_PLAN + (j in helpful) * strips_soft.PRIOR_HELPFUL
        assert prior[j].item() == pytest.approx(math.exp(bonus))
    assert prior[-1].item() == 1.0  # STAY
