"""Sokoban problems in and out of PDDL (PlanBench ``typed-sokoban``), moves as actions, samples.

`from_pddl` reads a parsed problem into a `Problem`: ``entities = ("robot", box...)`` (boxes in
file order), ``init`` = each entity's cell, ``goal`` = ``(box, cell)`` pairs, ``fixed`` = the
non-wall cells (LOC objects that are clear or occupied at the start; walls are the rest), and
``data`` = the `Grid` (every LOC, DIR and ``adjacent`` fact, for ``to_pddl`` and ``to_atoms``).
PDDLError names whatever does not fit: two robots, a box on a wall, a non-functional adjacency.
Each move is one PDDL action, ``(move from to dir)`` or ``(push rloc bloc floc dir box)``.
"""

from __future__ import annotations

import random
import re
from collections.abc import Iterable, Iterator, Sequence

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.deadline import NO_DEADLINE, Deadline
from task.domains.sokoban_grid import ROBOT, Grid, apply_move, check_move, grid
from task.errors import PDDLError, ProblemError
from task.problem import Action, Move, Problem
from task.symbolic import pddl_io, strips

NAME = "sokoban"
PDDL_DOMAIN = "typed-sokoban"
DOMAIN_FILE = "typed-sokoban.pddl"
DIRECTIONS = ("up", "down", "left", "right")  # column order when a problem uses these names
_ARITY = {"at-robot": 1, "at": 2, "adjacent": 3, "clear": 1}

# ------------------------------------------------------------------------------------ PDDL in


def _natural(name: str) -> tuple:
    return tuple((0, int(p)) if p.isdigit() else (1, p) for p in re.split(r"(\d+)", name) if p)


def _kinds(problem: PDDLProblem, order: Sequence[str] | None) -> dict[str, list[str]]:
    tags = {str(o.name).lower(): {str(t).lower() for t in o.type_tags} for o in problem.objects}
    names = list(order) if order else sorted(tags, key=_natural)
    if set(names) != set(tags):
        raise PDDLError(f"objects {sorted(tags)} do not match the order {names}")
    kinds: dict[str, list[str]] = {"loc": [], "dir": [], "box": []}
    for x in names:
        kind = [k for k in kinds if k in tags[x]]
        if len(kind) != 1:
            raise PDDLError(f"object {x} has type {sorted(tags[x])} (valid: LOC, DIR, BOX)")
        kinds[kind[0]].append(x)
    if ROBOT in names:
        raise PDDLError(f"object name {ROBOT!r} is reserved for the robot")
    return kinds


def _checked(atoms: Iterable[tuple], kinds: dict[str, list[str]], where: str) -> list[tuple]:
    want = {"at-robot": ("loc",), "at": ("box", "loc"), "adjacent": ("loc", "loc", "dir")}
    out = sorted(atoms)
    for atom in out:
        types = want.get(atom[0], ("loc",))
        if _ARITY.get(atom[0]) != len(atom) - 1 or any(
            a not in kinds[t] for a, t in zip(atom[1:], types, strict=True)
        ):
            raise PDDLError(f"{where} atom {strips.atom_str(atom)} is not a typed-sokoban atom")
    return out


def from_pddl(
    domain: Domain,
    problem: PDDLProblem,
    order: Sequence[str] | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> Problem:
    """The `Problem` of a parsed typed-sokoban problem (``order``: objects in file order;
    ``deadline`` is not looked at: the reading is linear in the problem)."""
    if not matches(domain):
        raise PDDLError(f"domain {domain.name} is not {PDDL_DOMAIN} (needs move/3, push/5)")
    kinds = _kinds(problem, order)
    if len(kinds["dir"]) > len(DIRECTIONS):
        raise PDDLError(f"{len(kinds['dir'])} directions {kinds['dir']}: at most 4 are supported")
    dirs = sorted(kinds["dir"], key=lambda d: DIRECTIONS.index(d) if d in DIRECTIONS else 4)
    init = _checked(strips.initial_state(problem), kinds, "init")
    robots = [a[1] for a in init if a[0] == "at-robot"]
    if len(robots) != 1:
        raise PDDLError(f"init places the robot {len(robots)} times (needs one (at-robot ...))")
    clear = {a[1] for a in init if a[0] == "clear"}
    place: dict[str, str] = {}
    for _, b, c in (a for a in init if a[0] == "at"):
        if b in place or c in place.values() or c in clear or c == robots[0]:
            raise PDDLError(f"init: (at {b} {c}) clashes with another box, clear or the robot")
        place[b] = c
    missing = [b for b in kinds["box"] if b not in place]
    if missing:
        raise PDDLError(f"init: box {missing[0]} has no (at {missing[0]} ...)")
    if robots[0] not in clear:
        raise PDDLError(f"init: the robot's cell {robots[0]} must be clear")
    adjacent = tuple(a[1:] for a in init if a[0] == "adjacent")
    if len({(a, d) for a, _, d in adjacent}) != len(adjacent):
        raise PDDLError("adjacent facts give some cell two neighbours in one direction")
    cells = tuple(c for c in kinds["loc"] if c in clear or c in place.values())
    goal = []
    for atom in _checked(strips.goal_atoms(problem), kinds, "goal"):
        if atom[0] != "at" or atom[2] not in cells:
            raise PDDLError(f"goal {strips.atom_str(atom)} is not (at box cell) on a free cell")
        goal.append(atom[1:])
    for what, seen in (("box", [b for b, _ in goal]), ("cell", [c for _, c in goal])):
        if len(set(seen)) != len(seen):
            raise PDDLError(f"goal places a {what} twice: {goal}")
    data = Grid(tuple(kinds["loc"]), tuple(dirs), tuple(kinds["box"]), adjacent, cells)
    init_cells = (robots[0], *(place[b] for b in kinds["box"]))
    return Problem(
        str(problem.name), NAME, (ROBOT, *kinds["box"]), init_cells, tuple(goal), cells, data
    )


def problem_from_text(domain: Domain, text: str, source: str = "<problem>") -> Problem:
    """Parse problem PDDL text (keeping the file's object order) into a `Problem`."""
    return pddl_io.problem_with(from_pddl, domain, text, source)


# ------------------------------------------------------------------------------ PDDL out


def to_atoms(problem: Problem, state: Sequence[str]) -> frozenset[tuple[str, ...]]:
    """Every typed-sokoban atom of ``state``: adjacent, at-robot, at, clear (lowercased)."""
    g = grid(problem)
    atoms = {("adjacent", *a) for a in g.adjacent} | {("at-robot", state[0])}
    atoms |= {("at", b, c) for b, c in zip(problem.entities[1:], state[1:], strict=True)}
    atoms |= {("clear", c) for c in g.cells if c not in state[1:]}
    return frozenset(atoms)


def to_pddl(problem: Problem) -> str:
    """PlanBench-style problem PDDL text of ``problem`` at its initial state."""
    g = grid(problem)
    lines = [f"(define (problem {problem.name})", f"(:domain {PDDL_DOMAIN})", "(:objects"]
    lines += [" ".join(g.dirs) + " - DIR"] + ([" ".join(g.boxes) + " - BOX"] if g.boxes else [])
    lines += [" ".join(g.locs) + " - LOC", ")", "(:init"]
    lines += [f"(adjacent {a} {b} {d})" for a, b, d in g.adjacent]
    lines += [f"(at {b} {c})" for b, c in zip(problem.entities[1:], problem.init[1:], strict=True)]
    lines += [f"(clear {c})" for c in g.cells if c not in problem.init[1:]]
    lines += [f"(at-robot {problem.init[0]})", ")", "(:goal", "(and"]
    lines += [f"(at {b} {c})" for b, c in problem.goal] + [")", ")", ")"]
    return "\n".join(lines) + "\n"


def to_actions(problem: Problem, moves: Sequence[Move], strict: bool = True) -> tuple:
    """One PDDL action per move, replayed from init (ProblemError on an illegal move unless
    ``strict=False``: then it is written as it stands, e.g. a move into a wall, so that a
    validator names it, and the replay goes on from the unchanged state)."""
    state, out = tuple(problem.init), []
    for move in moves:
        reason = check_move(problem, state, move)
        if reason is not None and strict:
            raise ProblemError(f"illegal {move}: {reason}")
        r, d = state[0], move.target
        one = grid(problem).ahead.get((r, d))
        two = grid(problem).ahead.get((one, d))
        if one in state[1:]:
            box = problem.entities[state.index(one, 1)]
            out.append(Action("push", (r, one, two or one, d, box)))
        else:
            out.append(Action("move", (r, one or r, d)))
        state = state if reason else apply_move(problem, state, move)
    return tuple(out)


# ------------------------------------------------------------------------------- samples

_STEP = {"up": (-1, 0), "down": (1, 0), "left": (0, -1), "right": (0, 1)}


def grid_problem(name: str, rows: int, cols: int, walls, robot, boxes, goals) -> Problem:
    """A problem on a rows x cols grid (PlanBench names ``f{r}-{c}f``); cells are (r, c)."""
    cell = [[f"f{r}-{c}f" for c in range(cols)] for r in range(rows)]
    locs = tuple(x for row in cell for x in row)
    adjacent = sorted(
        (cell[r][c], cell[r + dr][c + dc], d)
        for r in range(rows)
        for c in range(cols)
        for d, (dr, dc) in _STEP.items()
        if 0 <= r + dr < rows and 0 <= c + dc < cols
    )
    names = tuple(f"box{k}" for k in range(len(boxes)))
    cells = tuple(cell[r][c] for r in range(rows) for c in range(cols) if (r, c) not in walls)
    data = Grid(locs, DIRECTIONS, names, tuple(adjacent), cells)
    init = tuple(cell[r][c] for r, c in (robot, *boxes))
    goal = tuple((b, cell[r][c]) for b, (r, c) in zip(names, goals, strict=True))
    return Problem(name, NAME, (ROBOT, *names), init, goal, cells, data)


def random_problem(rows: int, cols: int, n_boxes: int, n_walls: int, seed: int) -> Problem:
    """A solvable random problem: boxes start on their goals and the robot pulls them back
    (the reverse of pushes) along a random walk; retried until some box is off its goal."""
    rng = random.Random(f"{rows}x{cols}-{n_boxes}-{n_walls}-{seed}")
    every = [(r, c) for r in range(rows) for c in range(cols)]
    while True:
        walls = set(rng.sample(every, n_walls))
        free = [x for x in every if x not in walls]
        goals = rng.sample(free, n_boxes)
        boxes, robot = list(goals), rng.choice([x for x in free if x not in goals])
        for _ in range(6 * (rows + cols)):
            dr, dc = rng.choice(list(_STEP.values()))
            to, behind = (robot[0] + dr, robot[1] + dc), (robot[0] - dr, robot[1] - dc)
            if to not in free or to in boxes:
                continue
            if behind in boxes and rng.random() < 0.8:
                boxes[boxes.index(behind)] = robot
            robot = to
        if boxes != goals:
            name = f"sokoban-{rows}x{cols}-b{n_boxes}-w{n_walls}-s{seed}"
            return grid_problem(name, rows, cols, walls, robot, boxes, goals)


def samples(seed: int) -> Iterator[Problem]:
    """Random solvable grids of 4x4 to 6x6 with a few walls and 1-2 boxes."""
    for rows, cols, boxes, walls in ((4, 4, 1, 1), (5, 5, 1, 3), (5, 5, 2, 2), (6, 6, 2, 4)):
        yield random_problem(rows, cols, boxes, walls, seed)


def pddl_domain_text() -> str:
    """The embedded typed-sokoban domain (``task/data/typed-sokoban.pddl``)."""
    from task import data

    return data.read_text(DOMAIN_FILE)


def matches(domain: Domain) -> bool:
    """Whether a parsed PDDL domain has typed-sokoban's actions and predicates (arities)."""
    from task.symbolic.signature import signature

    return signature(domain) == signature(pddl_io.parse_domain(pddl_domain_text()))
