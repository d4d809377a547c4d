"""Blocksworld: PDDL round trips, every bad input's one-line error, crisp moves and actions."""

from __future__ import annotations

import pytest

from task.domains import blocksworld as bw
from task.errors import PDDLError, ProblemError
from task.problem import TABLE, Action, Move, Problem
from task.symbolic import generate, pddl_io

# c on b on a; d on the table. Objects deliberately not in alphabetical order.
PROBLEM = """(define (problem tiny)
(:domain blocksworld-4ops)
(:objects d a b c )
(:init
(handempty)
(ontable d)
(ontable a)
(on b a)
(on c b)
(clear d)
(clear c)
)
(:goal
(and
(on a b)
(on d a))
)
)
"""


@pytest.fixture
def domain(bw_domain_path):
    return pddl_io.load_domain(bw_domain_path)


@pytest.fixture
def tiny(domain) -> Problem:
    return bw.problem_from_text(domain, PROBLEM, "tiny.pddl")


def _error(excinfo: pytest.ExceptionInfo, part: str) -> None:
    message = str(excinfo.value)
    assert "\n" not in message
    assert part in message, message


def test_from_pddl_keeps_file_order(tiny):
    entities, init = ("d", "a", "b", "c"), (TABLE, TABLE, "a", "b")
    assert tiny == Problem("tiny", "blocksworld", entities, init, (("a", "b"), ("d", "a")))
    assert bw.to_pddl(tiny) == PROBLEM


def test_from_pddl_without_order_sorts_naturally(domain):
    names = " ".join(generate.block_names(30))
    text = PROBLEM.replace("d a b c ", f"d a b c {names} ")
    extra = "".join(f"(ontable {x})\n(clear {x})\n" for x in generate.block_names(30))
    text = text.replace("(handempty)\n", "(handempty)\n" + extra)
    problem = bw.from_pddl(domain, pddl_io.parse_problem(text))
    assert problem.entities[:4] == ("a", "b", "b1", "b2")
    assert problem.entities.index("b10") == problem.entities.index("b9") + 1


@pytest.mark.parametrize(("n_blocks", "seed"), [(2, 0), (3, 1), (5, 2), (8, 3), (30, 4)])
def test_round_trip_generated(domain, bw_domain_path, tmp_path, n_blocks, seed):
    problem = generate.random_problem(n_blocks, seed)
    text = bw.to_pddl(problem)
    assert bw.problem_from_text(domain, text) == problem
    path = tmp_path / "p.pddl"
    path.write_text(text)
    assert bw.problem_from_files(bw_domain_path, path) == problem


def test_round_trip_ontable_goal(domain):
    problem = Problem("t", "blocksworld", ("b", "a"), ("a", TABLE), (("a", "b"), ("b", TABLE)))
    text = bw.to_pddl(problem)
    assert "(ontable b))" in text
    assert bw.problem_from_text(domain, text) == problem


@pytest.mark.shared
def test_planbench_files_round_trip_byte_exact(planbench_dir):
    root = planbench_dir / "blocksworld"
    domain = pddl_io.load_domain(root / "domain.pddl")
    paths = sorted((root / "instances").rglob("instance-*.pddl"))
    assert len(paths) == 602
    for path in paths:
        text = path.read_text()
        assert bw.to_pddl(bw.problem_from_text(domain, text, str(path))) == text.strip() + "\n"


INIT = "(handempty)\n(ontable d)\n(ontable a)\n(on b a)\n(on c b)\n(clear d)\n(clear c)\n"
GOAL = "(on a b)\n(on d a))"


@pytest.mark.parametrize(
    ("init", "goal", "part"),
    [
        (INIT.replace("(handempty)\n", ""), GOAL, "init lacks (handempty)"),
        (INIT.replace("(clear c)", "(holding c)"), GOAL, "init has (holding c)"),
        (INIT.replace("(ontable d)\n", ""), GOAL, "block d has no support"),
        (INIT + "(on d c)\n", GOAL, "d has two supports: c, table"),
        (INIT.replace("(ontable a)", "(on a c)"), GOAL, "init: cycle a on c on b on a"),
        (INIT + "(clear b)\n", GOAL, "(clear b) is inconsistent with (on c b)"),
        (INIT.replace("(clear d)\n", ""), GOAL, "nothing is on d but (clear d) is missing"),
        (INIT + "(on d b)\n", GOAL, "init: c and d are both on b"),
        (INIT + "(on z a)\n", GOAL, "init atom (on z a) names unknown object 'z'"),
        (
            INIT + "(heavy a)\n",
            GOAL,
            "init atom (heavy a): unknown predicate 'heavy' (valid: clear, handempty",
        ),
        (INIT, "(clear a))", "(clear a) in the goal cannot be expressed as a support relation"),
        (INIT, "(holding a))", "(holding a) in the goal cannot be expressed"),
        (INIT, "(on a q))", "goal atom (on a q) names unknown object 'q' (valid: d, a, b, c)"),
        (INIT, "(on a b)\n(on c b))", "unsolvable goal: a and c are both on b"),
        (INIT, "(on a a))", "unsolvable goal: (on a a) puts a on itself"),
        (INIT, "(on a b)\n(on b a))", "unsolvable goal: cycle a on b on a"),
        (INIT, "(on a b)\n(ontable a))", "unsolvable goal: a has two supports: b, table"),
    ],
)
def test_bad_problem_errors(domain, init, goal, part):
    text = PROBLEM.replace(INIT, init).replace(GOAL, goal)
    with pytest.raises(PDDLError) as excinfo:
        bw.problem_from_text(domain, text, "bad.pddl")
    _error(excinfo, part)
    assert str(excinfo.value).startswith("bad.pddl: ")


def test_handempty_goal_is_ignored(domain):
    text = PROBLEM.replace(GOAL, "(handempty)\n" + GOAL)
    assert bw.problem_from_text(domain, text).goal == (("a", "b"), ("d", "a"))


def test_not_blocksworld_domain(bw_domain_path):
    text = bw_domain_path.read_text().replace("(:action put-down", "(:action put-away")
    other = pddl_io.parse_domain(text, "other")
    with pytest.raises(PDDLError) as excinfo:
        bw.from_pddl(other, pddl_io.parse_problem(PROBLEM))
    _error(excinfo, "is not the 4-operator blocksworld (needs pick-up, put-down, stack, unstack)")


def test_problem_from_missing_file(bw_domain_path, tmp_path):
    with pytest.raises(PDDLError) as excinfo:
        bw.problem_from_files(bw_domain_path, tmp_path / "missing.pddl")
    _error(excinfo, "missing.pddl: no such file")


# ------------------------------------------------------------------------------------ crisp


def test_crisp_state(tiny):
    state = bw.initial_state(tiny)
    assert state == (TABLE, TABLE, "a", "b")
    assert bw.is_clear(tiny, state, "c") and bw.is_clear(tiny, state, TABLE)
    assert not bw.is_clear(tiny, state, "a")
    assert bw.unsatisfied_goals(tiny, state) == (("a", "b"), ("d", "a"))
    assert not bw.is_goal(tiny, state)


@pytest.mark.parametrize(
    ("move", "reason"),
    [
        (Move("c", TABLE), None),
        (Move("c", "d"), None),
        (Move("a", "d"), "a is not clear (b is on it)"),
        (Move("d", "b"), "target b is not clear (c is on it)"),
        (Move("c", "c"), "c cannot be moved onto itself"),
        (Move("c", "b"), "c is already on b"),
        (Move("d", TABLE), "d is already on table"),
    ],
)
def test_check_move(tiny, move, reason):
    assert bw.check_move(tiny, bw.initial_state(tiny), move) == reason


@pytest.mark.parametrize("move", [Move("z", TABLE), Move("c", "z"), Move(TABLE, "a")])
def test_unknown_block_in_move(tiny, move):
    with pytest.raises(ProblemError) as excinfo:
        bw.check_move(tiny, bw.initial_state(tiny), move)
    _error(excinfo, "unknown block")
    assert "valid: d, a, b, c" in str(excinfo.value)


def test_apply_moves_to_goal(tiny):
    moves = (Move("c", TABLE), Move("b", TABLE), Move("a", "b"), Move("d", "a"))
    state = bw.initial_state(tiny)
    for move in moves:
        state = bw.apply_move(tiny, state, move)
    assert bw.is_goal(tiny, state)
    with pytest.raises(ProblemError) as excinfo:
        bw.apply_move(tiny, state, Move("a", TABLE))
    _error(excinfo, "illegal move(a -> table): a is not clear (d is on it)")


def test_moves_actions_round_trip(tiny):
    moves = (Move("c", "d"), Move("b", TABLE), Move("b", "c"))
    actions = bw.moves_to_actions(tiny, moves)
    assert actions == (
        Action("unstack", ("c", "b")),
        Action("stack", ("c", "d")),
        Action("unstack", ("b", "a")),
        Action("put-down", ("b",)),
        Action("pick-up", ("b",)),
        Action("stack", ("b", "c")),
    )
    assert bw.actions_to_moves(tiny, actions) == moves
    with pytest.raises(ProblemError, match="illegal move"):
        bw.moves_to_actions(tiny, (Move("a", TABLE),))


@pytest.mark.parametrize(
    ("actions", "part"),
    [
        ([Action("unstack", ("c", "b"))], "plan ends holding c"),
        ([Action("pick-up", ("d",)), Action("pick-up", ("c",))], "action 2 (pick-up c): expected"),
        ([Action("stack", ("c", "d"))], "action 1 (stack c d): expected (pick-up x)"),
        ([Action("pick-up", ("d",)), Action("stack", ("c", "a"))], "the hand holds d, not c"),
        ([Action("unstack", ("c",))], "expected (pick-up x) or (unstack x y)"),
        ([Action("pick-up", ("q",))], "unknown block 'q'"),
        ([Action("pick-up", ("d",)), Action("stack", ("d", "q"))], "unknown block 'q'"),
    ],
)
def test_actions_to_moves_errors(tiny, actions, part):
    with pytest.raises(ProblemError) as excinfo:
        bw.actions_to_moves(tiny, actions)
    _error(excinfo, part)
