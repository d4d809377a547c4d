"""Logistics static facts and problem PDDL in and out (the IPC/PlanBench ``logistics-strips``).

Relational reading: the entities are the packages, trucks and airplanes (in that order, each in
file order) and the fixed targets are the locations. A crisp state is the support of every
entity: a package's location or the vehicle it is in, a vehicle's location. The static facts
(the city of each location, the airports, each truck's city) are a
`task.domains.logistics_map.LogisticsData` in ``Problem.data``; `make_problem` builds a
problem from checked parts. `from_pddl` reads the untyped problem by its type predicates (OBJ,
TRUCK, AIRPLANE, LOCATION, CITY, AIRPORT) and names whatever does not fit; `to_pddl` writes
PlanBench-style text; `to_atoms` gives every atom of a state.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Sequence

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.deadline import NO_DEADLINE, Deadline
from task.domains.logistics_map import LogisticsData
from task.errors import PDDLError, one_of
from task.problem import Problem
from task.symbolic import strips

NAME = "logistics"
PDDL_DOMAIN = "logistics-strips"
DOMAIN_FILE = "logistics-strips.pddl"
OPERATORS = ("load-truck", "load-airplane", "unload-truck", "unload-airplane", "drive-truck")
OPERATORS += ("fly-airplane",)
KINDS = {"obj": "package", "truck": "truck", "airplane": "airplane", "location": "location"}
KINDS |= {"city": "city"}  # type predicate -> kind (AIRPORT marks some locations)


def make_problem(name, kinds, city, airports, support, goal, order) -> Problem:
    """A logistics `Problem` from checked parts: ``kinds`` object -> kind (see ``KINDS``),
    ``city`` location -> city, ``support`` entity -> location or vehicle, ``goal`` pairs."""
    of = {k: tuple(x for x in order if kinds[x] == k) for k in KINDS.values()}
    entities, locations = of["package"] + of["truck"] + of["airplane"], of["location"]
    port = tuple(x for x in locations if x in airports)
    truck_city = tuple(city[support[t]] for t in of["truck"])
    data = LogisticsData(
        of["package"],
        of["truck"],
        of["airplane"],
        of["city"],
        tuple(city[x] for x in locations),
        port,
        truck_city,
    )
    init = tuple(support[x] for x in entities)
    return Problem(name, NAME, entities, init, tuple(goal), locations, data)


def _typed(atom: tuple, kinds: dict[str, str], wanted: Sequence[str], where: str) -> None:
    text = strips.atom_str(atom)
    if len(atom) - 1 != len(wanted):
        raise PDDLError(f"{where} atom {text} is not a {PDDL_DOMAIN} atom (wrong arity)")
    for arg, want in zip(atom[1:], wanted, strict=True):
        if arg not in kinds:
            raise PDDLError(f"{where} atom {text}: unknown object {one_of(arg, list(kinds))}")
        if kinds[arg] not in want.split("|"):
            raise PDDLError(f"{where} atom {text}: {arg} is a {kinds[arg]}, not a {want}")


def _kinds(atoms: frozenset, objects: Sequence[str]) -> dict[str, str]:
    found: dict[str, list[str]] = {x: [] for x in objects}
    for atom in (a for a in atoms if a[0] in KINDS and len(a) == 2 and a[1] in found):
        found[atom[1]].append(KINDS[atom[0]])
    for x, kinds in found.items():
        if len(kinds) != 1:
            what = "no type" if not kinds else "types " + ", ".join(sorted(kinds))
            wanted = " ".join(f"({k.upper()} {x})" for k in KINDS)
            raise PDDLError(f"init: object {x} has {what} (needs exactly one of {wanted})")
    return {x: kinds[0] for x, kinds in found.items()}


def _init(atoms: frozenset, kinds: dict[str, str]):
    city, airports, support = {}, [], {}
    located = ("package|truck|airplane", "location")
    wanted = {"airport": ("location",), "in-city": ("location", "city"), "at": located}
    wanted |= {"in": ("package", "truck|airplane")}
    for atom in sorted(atoms):
        pred, args = atom[0], atom[1:]
        if pred not in wanted and pred not in KINDS:
            raise PDDLError(f"init atom {strips.atom_str(atom)} is not a {PDDL_DOMAIN} atom")
        _typed(atom, kinds, (KINDS[pred],) if pred in KINDS else wanted[pred], "init")
        if pred == "airport":
            airports.append(args[0])
        elif pred == "in-city" and city.setdefault(args[0], args[1]) != args[1]:
            raise PDDLError(f"init: location {args[0]} is in two cities")
        elif pred in ("at", "in") and support.setdefault(args[0], args[1]) != args[1]:
            raise PDDLError(f"init: {args[0]} is in two places ({support[args[0]]}, {args[1]})")
    for x, kind in sorted(kinds.items()):
        if kind == "location" and x not in city:
            raise PDDLError(f"init: location {x} has no city (needs (in-city {x} ...))")
        if kind in ("package", "truck", "airplane") and x not in support:
            raise PDDLError(f"init: {kind} {x} is nowhere (needs (at {x} ...))")
        if kind == "airplane" and support[x] not in airports:
            raise PDDLError(f"init: airplane {x} is at {support[x]}, which is not an airport")
    return city, airports, support


def _goal(problem: PDDLProblem, kinds, city, airports, support) -> list[tuple[str, str]]:
    goal: dict[str, str] = {}
    for atom in strips.goal_atoms(problem):
        text = strips.atom_str(atom)
        if atom[0] != "at":
            raise PDDLError(f"goal atom {text} is not supported (goals are (at x location))")
        _typed(atom, kinds, ("package|truck|airplane", "location"), "goal")
        x, loc = atom[1:]
        if goal.setdefault(x, loc) != loc:
            raise PDDLError(f"unsolvable goal: {x} in two places ({goal[x]}, {loc})")
        if kinds[x] == "airplane" and loc not in airports:
            raise PDDLError(f"unsolvable goal {text}: {loc} is not an airport")
        if kinds[x] == "truck" and city[loc] != city[support[x]]:
            raise PDDLError(f"unsolvable goal {text}: truck {x} stays in {city[support[x]]}")
    return list(goal.items())


def from_pddl(
    domain: Domain,
    problem: PDDLProblem,
    order: Sequence[str] | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> Problem:
    """The relational `Problem` of a parsed logistics-strips problem.

    ``order``: the objects in file order (`pddl_io.object_order`); without it they are sorted
    naturally. PDDLError names what does not fit (an object without one type, a package in two
    places, an airplane off an airport, a goal that is not an ``at`` atom or cannot hold).
    ``deadline`` is not looked at: the reading is linear in the problem."""
    if not matches(domain):
        raise PDDLError(f"domain {domain.name} is not {PDDL_DOMAIN} (needs {', '.join(OPERATORS)})")
    names = {str(o.name).lower() for o in problem.objects}
    nat = lambda x: tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", x))  # noqa: E731
    objects = tuple(order) if order is not None else tuple(sorted(names, key=nat))
    if set(objects) != names or len(objects) != len(names):
        raise PDDLError(f"objects {sorted(names)} (in order {objects}) must be distinct")
    atoms = strips.initial_state(problem)
    kinds = _kinds(atoms, objects)
    city, airports, support = _init(atoms, kinds)
    goal = _goal(problem, kinds, city, airports, support)
    if "location" not in kinds.values():
        raise PDDLError(f"problem {problem.name} has no locations")
    return make_problem(str(problem.name), kinds, city, airports, support, goal, objects)


def matches(domain: Domain) -> bool:
    """Whether a parsed PDDL domain has logistics-strips' actions and predicates (arities)."""
    from task.symbolic.signature import signature

    return signature(domain) == signature(pddl_domain())


def pddl_domain_text() -> str:
    from task import data

    return data.read_text(DOMAIN_FILE)


@functools.cache
def pddl_domain() -> Domain:
    """The parsed embedded logistics-strips domain (``task/data/logistics-strips.pddl``)."""
    from task import data
    from task.symbolic import pddl_io

    return pddl_io.parse_domain(pddl_domain_text(), data.source(DOMAIN_FILE))


def to_atoms(problem: Problem, state: Sequence[str]) -> frozenset[tuple[str, ...]]:
    """Every PDDL atom of ``state``: type predicates, in-city, airports, at and in."""
    d: LogisticsData = problem.data
    atoms = {("obj", p) for p in d.packages} | {("truck", t) for t in d.trucks}
    atoms |= {("airplane", a) for a in d.airplanes} | {("city", c) for c in d.cities}
    atoms |= {("location", x) for x in problem.fixed} | {("airport", a) for a in d.airports}
    atoms |= {("in-city", x, c) for x, c in zip(problem.fixed, d.city, strict=True)}
    pairs = zip(problem.entities, state, strict=True)
    return frozenset(atoms | {("at" if s in problem.fixed else "in", x, s) for x, s in pairs})


def to_pddl(problem: Problem) -> str:
    """PlanBench-style problem PDDL text (objects: airplanes, cities, trucks, locations,
    packages; type predicates in upper case, as PlanBench writes them)."""
    d: LogisticsData = problem.data
    groups = (d.airplanes, d.cities, d.trucks, problem.fixed, d.packages)
    objects = "\n          ".join("".join(f"{x} " for x in g) for g in groups if g)
    init = [f"(AIRPLANE {a})" for a in d.airplanes] + [f"(CITY {c})" for c in d.cities]
    init += [f"(TRUCK {t})" for t in d.trucks]
    for x, c in zip(problem.fixed, d.city, strict=True):
        init += [f"(LOCATION {x})", f"(in-city {x} {c})"]
    init += [f"(AIRPORT {a})" for a in d.airports] + [f"(OBJ {p})" for p in d.packages]
    for x, s in zip(problem.entities, problem.init, strict=True):
        init.append(f"(at {x} {s})" if s in problem.fixed else f"(in {x} {s})")
    lines = [f"(define (problem {problem.name})", f"(:domain {PDDL_DOMAIN})"]
    lines += [f"(:objects {objects}", ")", "(:init", *(f"    {a}" for a in init), ")"]
    lines += ["(:goal", "    (and", *(f"        (at {x} {g})" for x, g in problem.goal)]
    return "\n".join([*lines, "    )", ")", ")"]) + "\n"
