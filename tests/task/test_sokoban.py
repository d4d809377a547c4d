"""The Sokoban domain: crisp rules, PDDL in/out, soft step vs crisp apply, bounds, planning."""

from __future__ import annotations

import collections
import dataclasses
import math
import random
from pathlib import Path

import pytest
import torch

from task.config import PlannerConfig
from task.domains import get_domain
from task.domains.match import recognise
from task.domains.sokoban import estimate, ready
from task.domains.sokoban_pddl import grid_problem, problem_from_text
from task.errors import PDDLError, ProblemError
from task.planner import plan
from task.problem import Move
from task.rollout import rollout
from task.symbolic import pddl_io, strips
from task.symbolic.validate import validate

SOK = get_domain("sokoban")
DOMAIN = pddl_io.parse_domain(SOK.pddl_domain_text())
PLANBENCH = Path(__file__).resolve().parents[3] / "shared/data/planbench/sokoban"


def level(text: str, name: str = "level"):
    """A problem from a map: ``#`` wall, ``@`` robot, digits boxes, letters their goals."""
    rows = text.strip().splitlines()
    at = {ch: (r, c) for r, row in enumerate(rows) for c, ch in enumerate(row)}
    walls = {(r, c) for r, row in enumerate(rows) for c, ch in enumerate(row) if ch == "#"}
    n = sum(ch.isdigit() for row in rows for ch in row)
    boxes, goals = [at[str(k)] for k in range(n)], [at["abcd"[k]] for k in range(n)]
    return grid_problem(name, len(rows), len(rows[0]), walls, at["@"], boxes, goals)


def cells(problem, *rc):
    return tuple(f"f{r}-{c}f" for r, c in rc)


def walk(problem, dirs):
    state = SOK.initial_state(problem)
    for d in dirs:
        state = SOK.apply_move(problem, state, Move("robot", d))
    return state


def pddl_problem(problem):
    return pddl_io.parse_problem(SOK.to_pddl(problem), problem.name, DOMAIN)


# ------------------------------------------------------------------------------------- crisp


def test_moves_pushes_walls_and_boxes():
    p = level("@.0.\n..#.\n.1..\n...a\n..b.")
    s = SOK.initial_state(p)
    assert SOK.check_move(p, s, Move("robot", "up")) == "up of f0-0f is the edge"
    assert SOK.apply_move(p, s, Move("robot", "down")) == cells(p, (1, 0), (0, 2), (2, 1))
    s = walk(p, ["right", "right"])  # the second step pushes box0
    assert s == cells(p, (0, 2), (0, 3), (2, 1))
    assert "edge" in SOK.check_move(p, s, Move("robot", "right"))
    s = walk(p, ["down", "right"])  # robot (1,1), box1 below it
    assert "wall" in SOK.check_move(p, walk(p, ["right", "down"]), Move("robot", "right"))
    assert SOK.check_move(p, s, Move("robot", "down")) is None
    q = level("@01.\n....\n..ab")
    assert "box1 is behind" in SOK.check_move(q, SOK.initial_state(q), Move("robot", "right"))
    with pytest.raises(ProblemError, match="illegal"):
        SOK.apply_move(q, SOK.initial_state(q), Move("robot", "right"))
    with pytest.raises(ProblemError, match="only the robot"):
        SOK.check_move(q, SOK.initial_state(q), Move("box0", "down"))
    with pytest.raises(ProblemError, match="unknown direction"):
        SOK.check_move(q, SOK.initial_state(q), Move("robot", "north"))
    assert [m.target for m in SOK.legal_moves(q, SOK.initial_state(q))] == ["down"]


def test_goal_and_decode():
    p = level("@0a")
    assert not SOK.is_goal(p, SOK.initial_state(p))
    assert SOK.is_goal(p, walk(p, ["right"]))
    assert SOK.decode(p, 0, 3, 2) == Move("robot", "right")
    assert SOK.decode(p, 1, 0, 2) is None and SOK.decode(p, 0, 4, 2) is None


# -------------------------------------------------------------------------------------- PDDL


def test_pddl_round_trip_atoms_and_recognition():
    p = level("@.0.\n..#.\n.1..\n...a\n..b.")
    text = SOK.to_pddl(p)
    q = problem_from_text(DOMAIN, text)
    assert q == p and q.data == p.data
    assert SOK.to_atoms(p, p.init) == strips.initial_state(pddl_problem(p))
    assert SOK.matches(DOMAIN) and recognise(DOMAIN) == "sokoban"
    assert not SOK.matches(pddl_io.parse_domain(get_domain("blocksworld").pddl_domain_text()))


def test_to_actions_validate_against_the_embedded_domain():
    p = level("....\n@0..\n....\n..a.")
    moves = [Move("robot", d) for d in ("right", "up", "right", "down", "down")]
    actions = SOK.to_actions(p, moves)
    assert [a.name for a in actions] == ["push", "move", "move", "push", "push"]
    assert actions[0].args == ("f1-0f", "f1-1f", "f1-2f", "right", "box0")
    assert validate(DOMAIN, pddl_problem(p), actions).valid
    wrong = [Move("robot", d) for d in ("up", "up", "down")]
    with pytest.raises(ProblemError, match="edge"):
        SOK.to_actions(p, wrong)
    check = validate(DOMAIN, pddl_problem(p), SOK.to_actions(p, wrong, strict=False))
    assert check.status.value == "inexecutable" and check.step == 2


def test_errors_name_what_does_not_fit():
    p = level("@0.\n..a")
    text = SOK.to_pddl(p)
    bad = {
        "(at-robot f0-0f)": "(at-robot f0-0f)\n(at-robot f1-0f)",
        "(at box0 f0-1f)": "(at box0 f0-0f)",
        "(at box0 f1-2f)\n)": "(at box0 f9-9f)\n)",
    }
    for old, new in bad.items():
        with pytest.raises(PDDLError):
            problem_from_text(DOMAIN, text.replace(old, new, 1))
    with pytest.raises(PDDLError, match="robot 2 times"):
        problem_from_text(
            DOMAIN, text.replace("(at-robot f0-0f)", "(at-robot f0-0f)\n(at-robot f1-0f)")
        )
    walled = text.replace("(clear f1-2f)\n", "")
    with pytest.raises(PDDLError, match="goal"):
        problem_from_text(DOMAIN, walled)
    bw = pddl_io.parse_domain(get_domain("blocksworld").pddl_domain_text())
    with pytest.raises(PDDLError, match="typed-sokoban"):
        SOK.from_pddl(bw, pddl_problem(p), ())


# -------------------------------------------------------------------------------------- soft


def _cases():
    """(problem, state) along seeded random legal walks from the domain's samples."""
    for seed in (0, 1):
        for problem in SOK.samples(seed):
            rng, state = random.Random(seed), SOK.initial_state(problem)
            for _ in range(8):
                yield problem, state
                state = SOK.apply_move(problem, state, rng.choice(SOK.legal_moves(problem, state)))


def _onehot(batch, col: int) -> torch.Tensor:
    M = torch.zeros(batch.action_mask.shape, dtype=torch.float64)
    M[..., -1] = 1.0
    M[0, 0, -1], M[0, 0, col] = 0.0, 1.0
    return M


def test_soft_step_equals_crisp_apply_on_onehot_states():
    counts = collections.Counter()
    for problem, state in _cases():
        batch = SOK.encode([problem], [state], torch.float64)
        assert torch.equal(SOK.consistency(batch.F0, batch), batch.F0)
        for col in range(4):
            move = SOK.decode(problem, 0, col, batch.n)
            F1, g = SOK.step(batch.F0, _onehot(batch, col), batch)
            if SOK.check_move(problem, state, move) is None:
                after = SOK.apply_move(problem, state, move)
                assert torch.equal(F1, SOK.encode([problem], [after], torch.float64).F0), move
                assert g[0, 0, col].item() == 1.0 and g.sum().item() == 1.0
                counts["push" if after[1:] != state[1:] else "move"] += 1
            else:
                assert g.abs().sum().item() == 0.0 and torch.equal(F1, batch.F0), move
                counts["illegal"] += 1
    assert min(counts.values()) >= 5, counts


def test_rows_stay_distributions_and_rollout_gradcheck():
    gen = torch.Generator().manual_seed(0)
    problems = [level("@.0.\n..#.\n.1..\n...a\n..b."), level("@0.\n..a")]
    batch = SOK.encode(problems, [p.init for p in problems], torch.float64)
    F = batch.F0
    for _ in range(4):
        logits = torch.randn(batch.action_mask.shape, generator=gen, dtype=torch.float64)
        M = torch.softmax(torch.where(batch.action_mask, logits, -1e9), -1)
        F, g = SOK.step(F, M, batch)
        assert (F >= 0).all() and (g >= 0).all() and g[:, 1:].abs().sum() == 0
        assert torch.allclose(F.sum(-1), torch.ones_like(F[..., 0]))
        F = SOK.consistency(F, batch)
        assert torch.allclose(F.sum(-1), torch.ones_like(F[..., 0]))
    small = SOK.encode(problems[1:], [problems[1].init], torch.float64)
    soft = dataclasses.replace(small, F0=small.F0 * 0.8 + 0.2 / small.F0.shape[-1])
    steps = torch.ones(1, 2, dtype=torch.bool)
    for kind in SOK.goal_losses:
        config = PlannerConfig(horizon=2, goal_loss=kind)
        x = torch.randn(
            (1, 2, *soft.action_mask.shape[1:]),
            generator=gen,
            dtype=torch.float64,
            requires_grad=True,
        )
        assert torch.autograd.gradcheck(
            lambda a, c=config: rollout(SOK, a, soft, steps, c).loss.sum(), (x,)
        )


# ------------------------------------------------------------------------------------ bounds


def test_dead_ends_have_an_infinite_lower_bound():
    corner = level("0...\n@...\n...a")  # a box in a corner off its goal
    edge = level("....\n.0..\n....\n.@.a")
    assert SOK.lower_bound(corner, corner.init) == math.inf
    assert SOK.lower_bound(edge, edge.init) < math.inf
    assert SOK.lower_bound(edge, walk(edge, ["up", "up", "left", "up"])) == math.inf  # 0 on edge
    pair = level(".01.ab\n......\n@.....")  # each alone could slide right; together frozen
    alone = dataclasses.replace(pair, init=cells(pair, (2, 0), (0, 1), (1, 2)))
    assert SOK.lower_bound(pair, pair.init) == math.inf
    assert SOK.lower_bound(alone, alone.init) < math.inf
    corridor = level("@.....\n.2....\n...1..\n....0.\n...##a\n...#.b\n...#.c")
    assert ready(corridor, corridor.init) == [False, False, True]
    assert SOK.lower_bound(corridor, corridor.init) < math.inf
    placed = dataclasses.replace(
        corridor, init=(*cells(corridor, (3, 5)), *cells(corridor, (4, 5), (2, 3), (1, 1)))
    )
    assert SOK.lower_bound(placed, placed.init) == math.inf  # 0 on its goal blocks the others


def test_lower_bound_is_admissible_and_estimate_above_it():
    problem = level("....\n.0..\n..1.\n@.ab")
    start = SOK.initial_state(problem)
    seen, order, before = {start}, [start], collections.defaultdict(list)
    for s in order:
        for t in (SOK.apply_move(problem, s, m) for m in SOK.legal_moves(problem, s)):
            before[t].append(s)
            order += [] if t in seen else [t]
            seen.add(t)
    dist = {s: 0 for s in order if SOK.is_goal(problem, s)}
    queue = list(dist)
    for t in queue:  # backward breadth-first search from the goal states
        for s in (s for s in before[t] if s not in dist):
            dist[s] = dist[t] + 1
            queue.append(s)
    dead = 0
    for s in order:
        bound, true, guess = (
            SOK.lower_bound(problem, s),
            dist.get(s, math.inf),
            estimate(problem, s),
        )
        assert bound <= true and guess >= bound and (guess == 0) == (true == 0)
        dead += bound == math.inf
    assert dead > 0 and SOK.lower_bound(problem, start) > 2 and len(dist) > 10


# ---------------------------------------------------------------------------------- planning


def test_plan_solves_a_small_problem_and_the_plan_validates():
    problem = level("....\n@0..\n...a")
    result = plan(problem, PlannerConfig(restarts=2, iters=20), seed=0)
    assert result.solved
    actions = SOK.to_actions(problem, result.plan.moves)
    assert validate(DOMAIN, pddl_problem(problem), actions).valid


def test_samples_are_small_unsolved_problems():
    problems = list(SOK.samples(0))
    assert {p.n - 1 for p in problems} == {1, 2}
    for p in problems:
        assert not SOK.is_goal(p, p.init) and SOK.lower_bound(p, p.init) < math.inf
        assert SOK.shape_key(p) == 1 and SOK.size(p) == p.n - 1


@pytest.mark.skipif(not PLANBENCH.is_dir(), reason="needs ../shared/data/planbench (shared data)")
def test_planbench_instances_read_and_write_back():
    """Uses the shared PlanBench data: the typed-sokoban domain and three instances."""
    domain = pddl_io.load_domain(PLANBENCH / "domain.pddl")
    assert SOK.matches(domain)
    for i in (0, 1, 17):
        text = pddl_io.read_text(PLANBENCH / f"instances/instance-{i}.pddl")
        problem = problem_from_text(domain, text)
        parsed = pddl_io.parse_problem(text, str(i), domain)
        assert SOK.to_atoms(problem, problem.init) == strips.initial_state(parsed)
        assert problem_from_text(domain, SOK.to_pddl(problem)) == problem
        assert SOK.lower_bound(problem, problem.init) < math.inf
