"""Pick-and-place domains bound to the motion layer: the declared binding (its checks against
the action schemas, its one-line errors), plans paired into moves (Blocksworld as the project's
own pairing gives them, Hanoi), and the Hanoi domain and its seeded problems."""

from __future__ import annotations

import json
import random

import pytest

from task import data
from task.domains.blocksworld_pddl import actions_to_moves, to_pddl
from task.errors import TampError
from task.problem import TABLE, Action, Move
from task.symbolic import pddl_io, strips
from task.symbolic.generate import random_problem
from task.symbolic.pickplace import binding, hanoi
from task.symbolic.pickplace.binding import BindingError, Role
from task.symbolic.search import optimal_length_strips, optimal_moves
from task.symbolic.validate import validate

BW = data.domain()
HANOI = pddl_io.parse_domain(hanoi.domain_text(), "hanoi")

BW_TOML = """
domain = "blocksworld-4ops"
[actions.pick-up]
role = "pick"
object = "?x"
[actions.unstack]
role = "pick"
object = "?x"
[actions.put-down]
role = "place"
object = "?x"
target = "table"
[actions.stack]
role = "place"
object = "?x"
target = "?y"
"""


def _bw(**change) -> str:
    """The blocksworld binding as JSON with some actions' entries replaced (None: dropped)."""
    actions = json.loads(binding.BLOCKSWORLD)["actions"]
    for name, entry in change.items():
        name = name.replace("_", "-")
        if entry is None:
            actions.pop(name)
        else:
            actions[name] = entry
    return json.dumps({"actions": actions})


def _hanoi_pddl(n_discs: int, seed: int, scattered: bool = False):
    return pddl_io.parse_problem(hanoi.problem_text(n_discs, seed, scattered), "hanoi", HANOI)


def _bfs_plan(domain, problem) -> tuple[Action, ...]:
    """A shortest plan by breadth-first search over the ground actions (small problems)."""
    actions = strips.ground_all(domain, problem)
    goal = strips.goal_atoms(problem)
    start = strips.initial_state(problem)
    parent = {start: None}
    frontier = [start]
    while frontier:
        following = []
        for state in frontier:
            if strips.holds(state, goal):
                plan = []
                while parent[state] is not None:
                    state, action = parent[state]
                    plan.append(action)
                return tuple(reversed(plan))
            for action, ground in actions:
                if strips.applicable(state, ground):
                    nxt = strips.apply(state, ground)
                    if nxt not in parent:
                        parent[nxt] = (state, action)
                        following.append(nxt)
        frontier = following
    raise AssertionError("no plan")


# ------------------------------------------------------------------------------------ binding


def test_blocksworld_binding_reads_alike_from_json_and_toml():
    from_json = binding.bind_text(binding.BLOCKSWORLD, BW)
    from_toml = binding.bind_text(BW_TOML, BW, fmt="toml")
    assert from_json == from_toml
    roles = {a.name: (a.role, a.object, a.target) for a in from_json.actions}
    assert roles == {
        "pick-up": (Role.PICK, 0, None),
        "unstack": (Role.PICK, 0, None),
        "put-down": (Role.PLACE, 0, TABLE),
        "stack": (Role.PLACE, 0, 1),
    }


def test_binding_file_by_suffix(tmp_path):
    path = tmp_path / "bw.toml"
    path.write_text(BW_TOML)
    assert binding.bind(binding.load(path), BW) == binding.bind_text(binding.BLOCKSWORLD, BW)
    with pytest.raises(BindingError, match=r"ends in '\.yaml' \(valid: \.json, \.toml\)"):
        binding.load(tmp_path / "bw.yaml")
    with pytest.raises(BindingError, match="cannot read"):
        binding.load(tmp_path / "missing.json")


@pytest.mark.parametrize(
    ("text", "fmt", "message"),
    [
        ("{", "json", r"not valid JSON"),
        ("actions = [", "toml", r"not valid TOML"),
        ("{}", "yaml", r"unknown binding format 'yaml' \(valid: json, toml\)"),
        ("[]", "json", r"expected a table with 'actions'"),
        ('{"actions": {}}', "json", r"'actions' must map at least one action"),
        ('{"action": {}}', "json", r"unknown key 'action' \(valid: domain, actions, scene\)"),
        ('{"actions": {"stack": 3}}', "json", r"action stack: expected a table of role, object"),
        (
            '{"actions": {"stack": {"role": "place", "obj": "?x"}}}',
            "json",
            r"unknown key 'obj' \(valid: role, object, target\)",
        ),
        ('{"actions": {"stack": {"object": "?x"}}}', "json", r"missing 'role'"),
        (
            '{"actions": {"stack": {"role": "grab", "object": "?x", "target": "?y"}}}',
            "json",
            r"unknown role 'grab' \(valid: pick, place, move\)",
        ),
        (
            '{"actions": {"pick-up": {"role": "pick", "object": "?x", "target": "table"}}}',
            "json",
            r"a pick names no target",
        ),
        (
            '{"actions": {"stack": {"role": "place", "object": "?x"}}}',
            "json",
            r"a place needs a target",
        ),
        ('{"actions": {"stack": {"role": "place", "object": 1}}}', "json", r"must be a name"),
    ],
)
def test_malformed_declarations_are_one_line_errors(text, fmt, message):
    with pytest.raises(BindingError, match=message) as info:
        binding.load_text(text, fmt)
    assert "\n" not in str(info.value)
    assert isinstance(info.value, TampError)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            _bw(stak={"role": "place", "object": "?x", "target": "?y"}),
            r"unknown action 'stak' \(valid: pick-up, put-down, stack, unstack\)",
        ),
        (
            _bw(stack={"role": "place", "object": "?z", "target": "?y"}),
            r"action stack: object '\?z' \(valid: \?x, \?y\)",
        ),
        (
            _bw(stack={"role": "place", "object": "?x", "target": "?w"}),
            r"action stack: target '\?w' \(valid: \?x, \?y\) \(or a region name\)",
        ),
        (
            _bw(stack={"role": "place", "object": "?x", "target": "?x"}),
            r"\?x is object and target",
        ),
        (
            _bw(stack={"role": "pick", "object": "?x"}),
            r"stack \(pick\) needs \(holding \?x\), which a pick makes: it places",
        ),
        (
            _bw(unstack={"role": "place", "object": "?x", "target": "?y"}),
            r"unstack \(place\) needs and deletes no atom of \?x that a pick adds",
        ),
        (
            _bw(stack={"role": "place", "object": "?y", "target": "?x"}),
            r"stack \(place\) needs and deletes no atom of \?y that a pick adds",
        ),
        (_bw(put_down=None, stack=None), r"pick actions \(pick-up, unstack\) but no place"),
        (_bw(pick_up=None, unstack=None), r"place actions \(put-down, stack\) but no pick"),
        (
            _bw(stack={"role": "move", "object": "?x", "target": "?y"}),
            r"stack \(move\) needs \(holding \?x\), which a pick makes",
        ),
        (
            json.dumps({"domain": "hanoi", "actions": json.loads(binding.BLOCKSWORLD)["actions"]}),
            r"binding is for domain 'hanoi', not 'blocksworld-4ops'",
        ),
    ],
)
def test_bindings_the_schemas_refute_are_one_line_errors(text, message):
    with pytest.raises(BindingError, match=message) as info:
        binding.bind_text(text, BW)
    assert "\n" not in str(info.value)


def test_a_move_must_place_its_object_on_its_target():
    bad = '{"actions": {"move": {"role": "move", "object": "?d", "target": "?from"}}}'
    with pytest.raises(BindingError, match=r"adds no atom of \?d and \?from"):
        binding.bind_text(bad, HANOI)
    not_moved = '{"actions": {"move": {"role": "move", "object": "?from", "target": "?to"}}}'
    with pytest.raises(BindingError, match=r"adds no atom of \?from and \?to"):
        binding.bind_text(not_moved, HANOI)


def test_an_action_that_changes_nothing_of_its_object_neither_picks_nor_places():
    looks = pddl_io.parse_domain(
        "(define (domain look) (:requirements :strips) (:predicates (on ?x ?y) (seen))"
        " (:action look :parameters (?x ?y) :precondition (on ?x ?y) :effect (seen)))"
    )
    text = '{"actions": {"look": {"role": "move", "object": "?x", "target": "?y"}}}'
    with pytest.raises(BindingError, match=r"look neither picks nor places \?x: it adds no atom"):
        binding.bind_text(text, looks)


# -------------------------------------------------------------------------------------- moves


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n_blocks", [3, 4, 5])
def test_blocksworld_moves_agree_with_the_project_pairing(n_blocks, seed):
    """The declared binding pairs an optimal 4-op plan into the moves the Blocksworld code
    (`actions_to_moves`) gives, and those moves validate as moves."""
    problem = random_problem(n_blocks, seed)
    pddl = pddl_io.parse_problem(to_pddl(problem), "bw", BW)
    moves = optimal_moves(problem)
    state = strips.initial_state(pddl)
    actions = []
    from task.symbolic.validate import move_actions

    for move in moves:
        for action in move_actions(move, state):
            state = strips.apply(state, strips.ground(BW, pddl, action))
            actions.append(action)
    assert validate(BW, pddl, actions).valid
    bound = binding.bind_text(binding.BLOCKSWORLD, BW)
    assert binding.to_moves(bound, actions) == actions_to_moves(problem, actions) == moves


@pytest.mark.parametrize(
    ("plan", "message"),
    [
        (
            [Action("pick-up", ("a",)), Action("pick-up", ("b",))],
            r"plan step 2 \(pick-up b\): the hand holds a \(picked at step 1\)",
        ),
        ([Action("stack", ("a", "b"))], r"plan step 1 \(stack a b\): places a, which no pick"),
        (
            [Action("unstack", ("a", "b")), Action("stack", ("c", "b"))],
            r"plan step 2 \(stack c b\): places c, but the hand holds a \(picked at step 1\)",
        ),
        (
            [Action("pick-up", ("a",)), Action("stack", ("a", "b")), Action("pick-up", ("c",))],
            r"plan ends holding c \(picked at step 3\)",
        ),
        (
            [Action("pick-up", ("a",)), Action("wave", ("a",))],
            r"plan step 2 \(wave a\): neither picks nor places \(bound: pick-up, unstack",
        ),
        ([Action("stack", ("a",))], r"plan step 1 \(stack a\): stack needs 2 arguments, got 1"),
    ],
)
def test_plans_that_do_not_pair_are_one_line_errors_naming_the_step(plan, message):
    bound = binding.bind_text(binding.BLOCKSWORLD, BW)
    with pytest.raises(BindingError, match=message) as info:
        binding.to_moves(bound, plan)
    assert "\n" not in str(info.value)


def test_a_move_while_holding_is_an_error():
    mixed = binding.Binding(
        "mixed",
        (
            binding.BoundAction("pick-up", Role.PICK, 0, None),
            binding.BoundAction("move", Role.MOVE, 0, 2),
        ),
    )
    plan = [Action("pick-up", ("a",)), Action("move", ("b", "c", "d"))]
    with pytest.raises(
        BindingError, match=r"step 2 \(move b c d\): moves b while the hand holds a"
    ):
        binding.to_moves(mixed, plan)


@pytest.mark.parametrize("n_discs", [3, 4])
def test_hanoi_plans_become_disc_moves(n_discs):
    """An optimal Hanoi plan becomes one (disc -> disc or peg) move per action; replayed on
    a support map, each move carries the top disc onto a larger top."""
    pddl = _hanoi_pddl(n_discs, seed=n_discs)
    plan = _bfs_plan(HANOI, pddl)
    assert validate(HANOI, pddl, plan).valid
    moves = binding.to_moves(binding.bind_text(hanoi.BINDING, HANOI), plan)
    assert moves == tuple(Move(a.args[0], a.args[2]) for a in plan)
    support = {a[1]: a[2] for a in strips.initial_state(pddl) if a[0] == "on"}
    size = {d: int(d[1:]) for d in hanoi.disc_names(n_discs)}
    for move in moves:
        assert move.entity not in support.values()  # the top of its stack
        assert move.target not in support.values()  # a clear target
        assert size[move.entity] < size.get(move.target, n_discs + 1)
        support[move.entity] = move.target
    goal = {a[1]: a[2] for a in strips.goal_atoms(pddl)}
    assert support == goal


# -------------------------------------------------------------------------------------- hanoi


def test_hanoi_domain_is_embedded_and_read_by_the_generic_lift():
    from task.domains.match import recognise

    assert hanoi.DOMAIN_FILE in data.names()
    assert str(HANOI.name) == hanoi.DOMAIN
    assert recognise(HANOI) == "strips"


@pytest.mark.parametrize("n_discs", [1, 2, 3, 4])
def test_hanoi_optimum_is_two_to_the_n_minus_one(n_discs):
    """Breadth-first search over the domain finds 2^n - 1 for every seeded tower problem."""
    for seed in range(3):
        pddl = _hanoi_pddl(n_discs, seed)
        assert optimal_length_strips(HANOI, pddl) == hanoi.optimal_length(n_discs)


def test_hanoi_problems_are_seeded_and_vary():
    assert hanoi.problem_text(4, 7) == hanoi.problem_text(4, 7)
    texts = {hanoi.problem_text(3, seed).split("\n", 1)[1] for seed in range(30)}
    assert len(texts) == 6  # start and goal: every ordered pair of distinct pegs
    scattered = {hanoi.problem_text(5, s, scattered=True).split("\n", 1)[1] for s in range(30)}
    assert len(scattered) > 10


@pytest.mark.parametrize("seed", range(10))
def test_hanoi_problems_are_legal_towers_with_static_sizes(seed):
    rng = random.Random(seed)
    n_discs = rng.randint(3, 5)
    pddl = _hanoi_pddl(n_discs, seed, scattered=rng.random() < 0.5)
    init = strips.initial_state(pddl)
    discs = hanoi.disc_names(n_discs)
    support = {a[1]: a[2] for a in init if a[0] == "on"}
    assert sorted(support) == sorted(discs)
    for disc, below in support.items():
        assert ("smaller", disc, below) in init
    covered = set(support.values())
    assert {a[1] for a in init if a[0] == "clear"} == set(discs + hanoi.PEGS) - covered
    smaller = {a[1:] for a in init if a[0] == "smaller"}
    assert smaller == {(a, b) for i, a in enumerate(discs) for b in (*discs[i + 1 :], *hanoi.PEGS)}
    assert not strips.holds(init, strips.goal_atoms(pddl))


def test_hanoi_disc_count_is_bounded():
    with pytest.raises(TampError, match=r"1 to 10 discs, got 0"):
        hanoi.problem_text(0, 0)
    with pytest.raises(TampError, match=r"1 to 10 discs, got 11"):
        hanoi.problem_text(11, 0)
