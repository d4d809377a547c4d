"""Logistics: crisp moves, PDDL round trips, actions against the validator, soft step vs crisp
apply, the lower bound against breadth-first search, a solved plan, and bad input's errors."""

from __future__ import annotations

import dataclasses
import itertools
import random
from collections import deque

import pytest
import torch

from task.config import PlannerConfig
from task.domains import get_domain
from task.domains import logistics_pddl as lp
from task.domains.match import recognise
from task.errors import PDDLError, ProblemError
from task.planner import plan
from task.problem import Move
from task.symbolic import pddl_io, strips
from task.symbolic.validate import validate

D = get_domain("logistics")

# Two cities; p0 waits at a non-airport location of c0 and must reach c1's non-airport one.
PROBLEM = """(define (problem tiny)
(:domain logistics-strips)
(:objects a0 c0 c1 t0 t1 l0-0 l0-1 l1-0 l1-1 p0 p1)
(:init
    (AIRPLANE a0) (CITY c0) (CITY c1) (TRUCK t0) (TRUCK t1)
    (LOCATION l0-0) (in-city l0-0 c0) (LOCATION l0-1) (in-city l0-1 c0)
    (LOCATION l1-0) (in-city l1-0 c1) (LOCATION l1-1) (in-city l1-1 c1)
    (AIRPORT l0-0) (AIRPORT l1-0) (OBJ p0) (OBJ p1)
    (at t0 l0-0) (at t1 l1-0) (at a0 l1-0) (at p0 l0-1) (in p1 t1))
(:goal (and (at p0 l1-1) (at p1 l1-0))))
"""
PLAN = [("t0", "l0-1"), ("p0", "t0"), ("t0", "l0-0"), ("p0", "l0-0"), ("p1", "l1-0")]
PLAN += [("a0", "l0-0"), ("p0", "a0"), ("a0", "l1-0"), ("p0", "l1-0"), ("p0", "t1")]
PLAN += [("t1", "l1-1"), ("p0", "l1-1")]


def _parse(text: str):
    domain = lp.pddl_domain()
    pp = pddl_io.parse_problem(text, "tiny.pddl", domain)
    return pp, D.from_pddl(domain, pp, pddl_io.object_order(text))


@pytest.fixture
def tiny():
    return _parse(PROBLEM)[1]


def _walks(seeds=(0, 1), length=8):
    """(problem, state) along seeded random legal walks from every sample problem."""
    for seed in seeds:
        for problem in D.samples(seed):
            rng, state = random.Random(seed), D.initial_state(problem)
            yield problem, state
            for _ in range(length):
                state = D.apply_move(problem, state, rng.choice(D.legal_moves(problem, state)))
                yield problem, state


def test_from_pddl_reads_entities_locations_and_static_facts(tiny):
    assert tiny.entities == ("p0", "p1", "t0", "t1", "a0")
    assert tiny.fixed == ("l0-0", "l0-1", "l1-0", "l1-1")
    assert tiny.init == ("l0-1", "t1", "l0-0", "l1-0", "l1-0")
    assert tiny.goal == (("p0", "l1-1"), ("p1", "l1-0"))
    assert tiny.data.airports == ("l0-0", "l1-0") and tiny.data.truck_city == ("c0", "c1")
    assert recognise(lp.pddl_domain()) == "logistics" and D.size(tiny) == 2
    assert D.shape_key(tiny) == (5, 4)


def test_crisp_legality_and_apply(tiny):
    state = D.initial_state(tiny)
    legal = {(m.entity, m.target) for m in D.legal_moves(tiny, state)}
    assert legal == {("p1", "l1-0"), ("t0", "l0-1"), ("t1", "l1-1"), ("a0", "l0-0")}
    reasons = {
        ("p0", "t0"): "p0 is at l0-1 but t0 is at l0-0",
        ("p0", "l0-0"): "p0 is not in a vehicle",
        ("p1", "l1-1"): "p1 is in t1, which is at l1-0",
        ("p1", "a0"): "unload it first",
        ("t0", "l1-1"): "truck t0 stays in its city",
        ("a0", "l0-1"): "l0-1 is not an airport",
        ("a0", "l1-0"): "already at l1-0",
        ("t0", "p0"): "cannot go into p0",
    }
    for (x, y), reason in reasons.items():
        assert reason in D.check_move(tiny, state, Move(x, y))
    after = D.apply_move(tiny, state, Move("t1", "l1-1"))
    assert after == ("l0-1", "t1", "l0-0", "l1-1", "l1-0")
    assert D.check_move(tiny, after, Move("p1", "l1-1")) is None  # p1 rode along


def test_plan_actions_validate_and_reach_the_goal(tiny):
    pp, problem = _parse(PROBLEM)
    moves = [Move(x, y) for x, y in PLAN]
    actions = D.to_actions(problem, moves)
    assert [str(a) for a in actions[:2]] == [
        "(drive-truck t0 l0-0 l0-1 c0)",
        "(load-truck p0 t0 l0-1)",
    ]
    assert validate(lp.pddl_domain(), pp, actions).valid
    state = D.initial_state(problem)
    for move in moves:
        state = D.apply_move(problem, state, move)
    assert D.is_goal(problem, state) and D.lower_bound(problem, state) == 0
    assert D.lower_bound(problem, problem.init) <= len(moves)
    bad = [*moves[:3], Move("p0", "l0-1")]  # p0 rides in t0, now at l0-0
    with pytest.raises(ProblemError, match="illegal"):
        D.to_actions(problem, bad)
    result = validate(lp.pddl_domain(), pp, D.to_actions(problem, bad, strict=False))
    assert result.status.value == "inexecutable" and result.step == 4


def test_pddl_round_trip_and_atoms():
    for problem in itertools.chain(*(D.samples(s) for s in range(3))):
        text = D.to_pddl(problem)
        pp, back = _parse(text)
        assert back == problem and back.data == problem.data
        assert D.to_atoms(problem, problem.init) == strips.initial_state(pp)
        assert set(strips.goal_atoms(pp)) == {("at", x, g) for x, g in problem.goal}


def test_soft_step_equals_crisp_apply_and_actions_replay():
    checked = {"legal": 0, "illegal": 0}
    domain = lp.pddl_domain()
    for problem, state in _walks():
        batch = D.encode([problem], [state], torch.float64)
        n, a = batch.n, batch.action_mask.shape[-1]
        pp = pddl_io.parse_problem(D.to_pddl(problem), "x", domain)
        for x, y in itertools.product(range(problem.n), range(a - 1)):
            move = D.decode(problem, x, y, n)
            if move is None:
                continue
            M = torch.zeros(1, n, a, dtype=torch.float64)
            M[0, :, -1], M[0, x, -1], M[0, x, y] = 1.0, 0.0, 1.0
            F1, g = D.step(batch.F0, M, batch)
            if D.check_move(problem, state, move) is None:
                after = D.apply_move(problem, state, move)
                assert torch.equal(F1, D.encode([problem], [after], torch.float64).F0), move
                assert g.sum().item() == 1.0 and batch.action_mask[0, x, y]
                (action,) = D.to_actions(dataclasses.replace(problem, init=state), [move])
                ground = strips.ground(domain, pp, action)
                atoms = D.to_atoms(problem, state)
                assert strips.applicable(atoms, ground)
                assert strips.apply(atoms, ground) == D.to_atoms(problem, after)
                checked["legal"] += 1
            else:
                assert g.abs().sum().item() == 0.0 and torch.equal(F1, batch.F0), move
                checked["illegal"] += 1
    assert min(checked.values()) >= 100, checked


def test_soft_rows_stay_distributions_and_goal_terms_are_smooth():
    gen = torch.Generator().manual_seed(0)
    for problem in D.samples(0):
        batch = D.encode([problem], [problem.init], torch.float64)
        F = torch.softmax(torch.randn(batch.F0.shape, generator=gen, dtype=torch.float64), -1)
        M = torch.softmax(torch.randn(batch.action_mask.shape, generator=gen), -1).double()
        F1, g = D.step(F, M * batch.action_mask, batch)
        assert torch.allclose(D.consistency(F1, batch).sum(-1), torch.ones(1, batch.n).double())
        assert (g >= 0).all()
        for kind in D.goal_losses:
            Fg = F.clone().requires_grad_(True)
            loss = lambda F, k=kind, b=batch: D.goal_loss(F, b, k)  # noqa: E731
            assert torch.autograd.gradcheck(loss, (Fg,))
        crisp = D.goal_loss(batch.F0, batch, "potential").item()
        assert crisp >= D.lower_bound(problem, problem.init)  # a route-sum overestimate


def _optimal(problem) -> int:
    start, seen = D.initial_state(problem), set()
    queue = deque([(start, 0)])
    while queue:
        state, depth = queue.popleft()
        if D.is_goal(problem, state):
            return depth
        for move in D.legal_moves(problem, state):
            nxt = D.apply_move(problem, state, move)
            if nxt not in seen:
                seen.add(nxt)
                queue.append((nxt, depth + 1))
    raise AssertionError("unsolvable sample")


def test_lower_bound_is_admissible_on_small_samples():
    for problem in list(D.samples(0))[:3]:
        bound = D.lower_bound(problem, problem.init)
        assert 0 < bound <= _optimal(problem), problem.name


def test_plan_solves_a_small_problem(tiny):
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # tiny tensors: one thread is faster, and steady on a busy machine
    try:
        result = plan(tiny, PlannerConfig(), seed=0)
    finally:
        torch.set_num_threads(threads)
    assert result.solved
    pp = _parse(PROBLEM)[0]
    assert validate(lp.pddl_domain(), pp, D.to_actions(tiny, result.plan.moves)).valid


@pytest.mark.parametrize(
    ("old", "new", "part"),
    [
        ("(at p0 l0-1)", "(at p0 l0-1) (in p0 t0)", "p0 is in two places"),
        ("(OBJ p1)", "", "object p1 has no type"),
        ("(at a0 l1-0)", "(at a0 l1-1)", "not an airport"),
        ("(and (at p0 l1-1)", "(and (in p0 t1)", "goals are (at x location)"),
        ("(at p1 l1-0))", "(at t0 l1-0))", "truck t0 stays in c0"),
        ("(in-city l1-1 c1)", "", "location l1-1 has no city"),
        ("(at t0 l0-0)", "(at t0 c0)", "c0 is a city, not a location"),
    ],
)
def test_bad_pddl_gets_one_line_errors(old, new, part):
    with pytest.raises(PDDLError) as excinfo:
        _parse(PROBLEM.replace(old, new, 1))
    assert part in str(excinfo.value) and "\n" not in str(excinfo.value)


def test_unknown_names_list_the_valid_ones(tiny):
    state = D.initial_state(tiny)
    with pytest.raises(ProblemError, match=r"'p9' \(valid: p0, p1, t0, t1, a0\)"):
        D.check_move(tiny, state, Move("p9", "l0-0"))
    with pytest.raises(ProblemError, match="unknown vehicle or location 'x'"):
        D.apply_move(tiny, state, Move("p0", "x"))
    with pytest.raises(ProblemError, match="unknown goal loss 'towers'"):
        D.goal_loss(D.encode([tiny], [state]).F0, D.encode([tiny], [state]), "towers")
    with pytest.raises(ProblemError, match="unknown vehicle or location 'x'"):
        D.to_actions(tiny, [Move("p0", "x")], strict=False)
    with pytest.raises(ProblemError, match="no logistics-strips action"):
        D.to_actions(tiny, [Move("t0", "p0")], strict=False)


@pytest.mark.shared
def test_planbench_instances_read_round_trip_and_validate(planbench_dir):
    """Reads ../shared PlanBench Logistics; skips without it."""
    root = planbench_dir / "logistics"
    domain = pddl_io.load_domain(root / "domain.pddl")
    assert D.matches(domain)
    for i in (1, 50, 150, 200, 286):
        text = pddl_io.read_text(root / "instances" / f"instance-{i}.pddl")
        pp = pddl_io.parse_problem(text, f"instance-{i}", domain)
        problem = D.from_pddl(domain, pp, pddl_io.object_order(text))
        assert D.to_atoms(problem, problem.init) == strips.initial_state(pp)
        assert _parse(D.to_pddl(problem))[1] == problem
        assert 0 < D.lower_bound(problem, problem.init) < float("inf")
