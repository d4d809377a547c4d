"""Unsolvable problems are proved so (`task.symbolic.proofs`) and told apart from a planner out
of budget by ``tamp plan``.

The problems are generated here in each hand-written domain's PDDL (Blocksworld, Logistics,
Sokoban) and in generic STRIPS domains, each under its own names and under a renaming of its
predicates, actions and objects (`_renamed`: the proofs read the PDDL's structure, never its
names). Renamed variants from `task.domains.match` can join ``CASES`` the same way.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tamp.cli import main
from tamp.cli import plan as commands
from task import data
from task.problem import Move, Plan, PlanResult, PlanStatus
from task.symbolic import ground, pddl_io, strips
from task.symbolic.proofs import Proof, mutex, prove_unsolvable
from task.symbolic.strips_task import StripsTask

BLOCKS = data.read_text("blocksworld-4ops.pddl")
LOGISTICS = data.read_text("logistics-strips.pddl")
SOKOBAN = data.read_text("typed-sokoban.pddl")
GRIPPER = (
    (Path(__file__).resolve().parents[1] / "fixtures" / "pddl_styles")
    .joinpath("pyperplan-gripper-domain.pddl")
    .read_text()
)
HOLES = """(define (domain holes)
  (:predicates (out ?p) (free ?h) (done ?p))
  (:action put
    :parameters (?p ?h)
    :precondition (and (out ?p) (free ?h))
    :effect (and (done ?p) (not (out ?p)) (not (free ?h)))))"""
LINKS = """(define (domain links)
  (:predicates (free ?x) (edge ?x ?y))
  (:action link
    :parameters (?x ?y)
    :precondition (free ?x)
    :effect (and (edge ?x ?y) (not (free ?x)))))"""


def _blocks(goal: str, n: int = 3) -> str:
    names = "abcdefgh"[:n]
    table = " ".join(f"(ontable {x}) (clear {x})" for x in names)
    return (
        f"(define (problem bw) (:domain blocksworld-4ops) (:objects {' '.join(names)})"
        f" (:init (handempty) {table}) (:goal (and {goal})))"
    )


def _logistics(goal: str, truck_in_city2: bool = False) -> str:
    """Two cities: c1 with post office l1 and airport a1 (a truck, an airplane), c2 with post
    office l2 only (no airport; a truck only if ``truck_in_city2``)."""
    truck2 = "(TRUCK t2) (at t2 l2)" if truck_in_city2 else ""
    return f"""(define (problem log) (:domain logistics-strips)
  (:objects p1 t1 t2 pl1 l1 a1 l2 c1 c2)
  (:init (OBJ p1) (TRUCK t1) (AIRPLANE pl1) (CITY c1) (CITY c2)
         (LOCATION l1) (LOCATION a1) (AIRPORT a1) (LOCATION l2)
         (in-city l1 c1) (in-city a1 c1) (in-city l2 c2)
         (at t1 l1) (at pl1 a1) (at p1 l1) {truck2})
  (:goal (and {goal})))"""


def _sokoban(box: str, goal: str, robot: str = "f1-1f", size: int = 4) -> str:
    """An open ``size`` x ``size`` room (no inner walls), one box."""
    cells = [f"f{r}-{c}f" for r in range(size) for c in range(size)]
    steps = {"up": (-1, 0), "down": (1, 0), "left": (0, -1), "right": (0, 1)}
    adjacent = [
        f"(adjacent f{r}-{c}f f{r + dr}-{c + dc}f {d})"
        for r in range(size)
        for c in range(size)
        for d, (dr, dc) in steps.items()
        if 0 <= r + dr < size and 0 <= c + dc < size
    ]
    clear = [f"(clear {x})" for x in cells if x != box]
    return f"""(define (problem soko) (:domain typed-sokoban)
  (:objects up down left right - DIR box0 - BOX {" ".join(cells)} - LOC)
  (:init (at-robot {robot}) (at box0 {box}) {" ".join(clear)} {" ".join(adjacent)})
  (:goal (and (at box0 {goal}))))"""


def _gripper(goal: str) -> str:
    return f"""(define (problem grip) (:domain gripper-strips)
  (:objects rooma roomb ball1 ball2 left right)
  (:init (room rooma) (room roomb) (ball ball1) (ball ball2) (gripper left) (gripper right)
         (at-robby rooma) (free left) (free right) (at ball1 rooma) (at ball2 rooma))
  (:goal (and {goal})))"""


LINKS_PROBLEM = """(define (problem ring) (:domain links) (:objects a b c)
  (:init (free a) (free b) (free c))
  (:goal (and (edge a b) (edge b c) (edge c a))))"""
HOLES_PROBLEM = """(define (problem three-in-two) (:domain holes) (:objects p1 p2 p3 h1 h2)
  (:init (out p1) (out p2) (out p3) (free h1) (free h2))
  (:goal (and (done p1) (done p2) (done p3))))"""

# (name, domain text, problem text, method, words the reason names)
UNSOLVABLE = [
    ("bw-cycle", BLOCKS, _blocks("(on a b) (on b c) (on c a)"), "invariant", ["(on c a)", "cycle"]),
    ("bw-two-on-one", BLOCKS, _blocks("(on a c) (on b c)"), "h2", ["(on a c)", "(on b c)"]),
    ("bw-one-on-two", BLOCKS, _blocks("(on a b) (on a c)"), "h2", ["(on a b)", "(on a c)"]),
    ("bw-on-itself", BLOCKS, _blocks("(on a a)"), "h2", ["(on a a)"]),
    ("bw-long-cycle", BLOCKS, _blocks("(on a b) (on b c) (on c d) (on d a)", 8), "invariant", []),
    ("logistics-no-way", LOGISTICS, _logistics("(at p1 l2)"), "relaxed", ["(at p1 l2)"]),
    ("logistics-two-places", LOGISTICS, _logistics("(at p1 l1) (at p1 a1)"), "h2", ["(at p1 a1)"]),
    ("sokoban-corner", SOKOBAN, _sokoban("f0-0f", "f2-2f"), "relaxed", ["(at box0 f2-2f)"]),
    ("gripper-both-left", GRIPPER, _gripper("(carry ball1 left) (carry ball2 left)"), "h2", []),
    ("holes", HOLES, HOLES_PROBLEM, "exhaustive", ["reachable states"]),
]
SOLVABLE = [
    ("bw-tower", BLOCKS, _blocks("(on a b) (on b c)", 5)),
    ("logistics-truck", LOGISTICS, _logistics("(at p1 a1)", truck_in_city2=True)),
    ("sokoban-open", SOKOBAN, _sokoban("f1-2f", "f2-2f", robot="f1-1f")),
    ("gripper", GRIPPER, _gripper("(at ball1 roomb) (at ball2 roomb)")),
    ("links-cycle", LINKS, LINKS_PROBLEM),
]


def _renamed(*texts: str) -> tuple[str, ...]:
    """``texts`` with every predicate, action and object name replaced by a meaningless one
    (the same map for all), keywords and variables kept."""
    words = sorted(
        {w for t in texts for w in re.findall(r"(?<![?:\w-])[a-z][\w-]*", t.lower())}
        - {"define", "domain", "problem", "and", "not", "either", "object"}
    )
    names = {w: f"n{k}x" for k, w in enumerate(words)}

    def rename(text: str) -> str:
        return re.sub(
            r"(?<![?:\w-])[A-Za-z][\w-]*",
            lambda m: names.get(m.group(0).lower(), m.group(0)),
            re.sub(r";[^\n]*", "", text),
        )

    return tuple(rename(t) for t in texts)


def _prove(domain_text: str, problem_text: str, **kwargs) -> Proof:
    domain = pddl_io.parse_domain(domain_text, "domain")
    return prove_unsolvable(
        domain, pddl_io.parse_problem(problem_text, "problem", domain), **kwargs
    )


@pytest.mark.parametrize("renamed", [False, True], ids=["own-names", "renamed"])
@pytest.mark.parametrize(("name", "domain", "problem", "method", "named"), UNSOLVABLE)
def test_unsolvable_problems_are_proved(name, domain, problem, method, named, renamed):
    if renamed:
        domain, problem = _renamed(domain, problem)
        named = [] if named and "(" in named[0] else named
    proof = _prove(domain, problem, exhaustive=True)
    assert proof.unsolvable and proof.method == method, proof
    assert all(word in proof.reason for word in named), proof.reason
    assert "\n" not in proof.reason


@pytest.mark.parametrize(("name", "domain", "problem"), SOLVABLE)
def test_solvable_problems_are_never_called_unsolvable(name, domain, problem):
    proof = _prove(domain, problem, exhaustive=True)
    assert not proof.unsolvable, proof
    assert proof.method == "" and "solvable" in proof.reason


def test_exhaustive_search_is_what_proves_three_in_two():
    """h^2 sees every pair of goal atoms reachable; only the search sees the triple is not."""
    assert not _prove(HOLES, HOLES_PROBLEM).unsolvable
    assert not _prove(HOLES, HOLES_PROBLEM, exhaustive=True, max_states=5).unsolvable
    assert (
        "stopped at 5 states" in _prove(HOLES, HOLES_PROBLEM, exhaustive=True, max_states=5).reason
    )


def _naive_h2(task) -> set[frozenset]:
    """h^2 by its definition, over sets of atoms (the reference for `mutex.h2`)."""
    pairs = {frozenset((p, q)) for p in task.init for q in task.init}
    changed = True
    while changed:
        changed = False
        for e in task.effects:
            if not all(frozenset((p, q)) in pairs for p in e.pre_pos for q in e.pre_pos):
                continue
            for p in e.add:
                for q in task.atoms:
                    kept = q not in e.delete and frozenset((q, q)) in pairs
                    kept = kept and all(frozenset((q, r)) in pairs for r in e.pre_pos)
                    if (q in e.add or kept) and frozenset((p, q)) not in pairs:
                        pairs.add(frozenset((p, q)))
                        changed = True
    return pairs


@pytest.mark.parametrize(
    ("domain", "problem"),
    [
        (BLOCKS, _blocks("(on a b)", 4)),
        (LOGISTICS, _logistics("(at p1 l2)", truck_in_city2=True)),
        (SOKOBAN, _sokoban("f1-2f", "f2-2f", size=3)),
        (GRIPPER, _gripper("(at ball1 roomb)")),
        (HOLES, HOLES_PROBLEM),
    ],
    ids=["blocksworld", "logistics", "sokoban", "gripper", "holes"],
)
def test_h2_matches_its_definition(domain, problem):
    parsed = pddl_io.parse_domain(domain, "d")
    pddl_problem = pddl_io.parse_problem(problem, "p", parsed)
    grounding = ground.reachable(parsed, pddl_problem)
    task = StripsTask.build(
        grounding.actions, strips.goal_atoms(pddl_problem), parsed, pddl_problem
    )
    found = mutex.h2(task)
    ours = {
        frozenset((task.atoms[i], task.atoms[j]))
        for i, j in zip(*found.pairs.nonzero(), strict=True)
    }
    assert ours == _naive_h2(task)
    assert (found.pairs == found.pairs.T).all()


def test_a_partial_h2_fixpoint_proves_nothing():
    """Out of time, h^2 stops before its fixpoint, where every unreached pair would look
    like a mutex: it must say it ran out of time, not call the problem unsolvable."""
    cycle = _blocks("(on a b) (on b c) (on c a)")
    proof = _prove(BLOCKS, cycle, time_limit_s=0.0)
    assert not proof.unsolvable and "h^2 ran out of time" in proof.reason
    assert "h^2 skipped" in _prove(BLOCKS, cycle, max_atoms=3).reason


def test_a_cycle_of_a_relation_that_may_loop_is_not_called_unsolvable():
    """``edge`` gains edges out of any free node, so the acyclicity invariant does not hold."""
    assert not _prove(LINKS, LINKS_PROBLEM).unsolvable


def _write(tmp_path: Path, domain: str, problem: str) -> list[str]:
    (tmp_path / "d.pddl").write_text(domain)
    (tmp_path / "p.pddl").write_text(problem)
    return [str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl")]


@pytest.mark.parametrize(
    ("domain", "problem", "reason"),
    [
        (
            BLOCKS,
            _blocks("(on a b) (on b c) (on c a)"),
            "goal atoms (on a b) (on b c) (on c a) form a cycle",
        ),
        (LOGISTICS, _logistics("(at p1 l2)"), "goal (at p1 l2) is unreachable"),
        (SOKOBAN, _sokoban("f0-0f", "f2-2f"), "goal (at box0 f2-2f) is unreachable"),
        (HOLES, HOLES_PROBLEM, "none of the"),
    ],
    ids=["blocksworld", "logistics", "sokoban", "holes"],
)
def test_tamp_plan_says_unsolvable_with_the_reason(domain, problem, reason, capsys, tmp_path):
    assert (
        main(
            [
                "plan",
                *_write(tmp_path, domain, problem),
                "--max-windows",
                "1",
                "--restarts",
                "2",
                "--iters",
                "5",
            ]
        )
        == 1
    )
    out = capsys.readouterr().out
    assert out.startswith(f"unsolvable: {reason}"), out
    assert "(" not in out.splitlines()[0].split(":")[0]  # no plan line before it


def test_tamp_plan_out_of_budget_says_no_plan_found_within_it(capsys, tmp_path):
    """Solvable, but one window of one restart cannot reach a 5-block tower: the budget is
    named, the problem is not called unsolvable, no plan is printed."""
    files = _write(tmp_path, BLOCKS, _blocks("(on a b) (on b c) (on c d) (on d e)", 5))
    argv = [
        "plan",
        *files,
        "--max-windows",
        "1",
        "--restarts",
        "1",
        "--iters",
        "1",
        "--horizon",
        "1",
        "--lookahead-share",
        "0",
    ]
    assert main(argv) == 1
    out = capsys.readouterr().out
    assert out.startswith("no plan found within 1 window: goal not reached"), out
    assert "unsolvable:" not in out and "; cost =" not in out
    assert "found a plan of 8 actions (solvable)" in out


def test_tamp_plan_json_says_unsolvable(capsys, tmp_path):
    files = _write(tmp_path, BLOCKS, _blocks("(on a c) (on b c)"))
    assert main(["plan", *files, "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["status"] == "unsolvable" and report["method"] == "h2"
    assert report["actions"] == [] and not report["valid"]


@pytest.mark.parametrize(
    "moves",
    [(Move("a", "b"),), (Move("c", "a"), Move("a", "b"))],
    ids=["goal-not-reached", "illegal-move"],
)
def test_tamp_plan_never_prints_a_plan_that_does_not_validate(moves, capsys, tmp_path, monkeypatch):
    """A planner that claims success with a plan that misses the goal (or breaks a rule):
    the validator's line, exit 1, and no plan on stdout or in ``--out``."""

    def claims_success(problem, config, seed, costs=None, deadline=None):
        return PlanResult(
            PlanStatus.SOLVED, Plan(moves), problem, None, {"windows": 1, "time_s": 0}
        )

    monkeypatch.setattr(commands, "plan", claims_success)
    out = tmp_path / "plan.txt"
    files = _write(tmp_path, BLOCKS, _blocks("(on a b) (on b c)"))
    assert main(["plan", *files, "--out", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "; cost =" not in printed and "(stack" not in printed, printed
    assert printed.startswith(("NON_GOAL_REACHING", "INEXECUTABLE")), printed
    assert not out.exists()
