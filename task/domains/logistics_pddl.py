"""Logistics static facts and problem PDDL in and out (the IPC/PlanBench ``logistics-strips``).

Relational reading: the entities are the packages, trucks and airplanes (in that order, each in
file order) and the fixed targets are the locations. A crisp state is the support of every
entity: a package's location or the vehicle it is in, a vehicle's location. The static facts
(the city of each location, the airports, each truck's city) are a `LogisticsData` in
``Problem.data``; `routes` gives the shortest static package routes between locations.
`from_pddl` reads the untyped problem by its type predicates (OBJ, TRUCK, AIRPLANE, LOCATION,
CITY, AIRPORT) and names whatever does not fit; `to_pddl` writes PlanBench-style text;
`to_atoms` gives every atom of a state; `random_problem` draws small problems named as
PlanBench names them (a0, c0, t0, l0-0, p0; l<c>-0 is city c's airport).
"""

from __future__ import annotations

import functools
import itertools
import math
import random
import re
from collections.abc import Sequence
from dataclasses import dataclass

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.errors import PDDLError, ProblemError, one_of
from task.problem import Problem
from task.symbolic import strips

NAME = "logistics"
PDDL_DOMAIN = "logistics-strips"
DOMAIN_FILE = "logistics-strips.pddl"
OPERATORS = ("load-truck", "load-airplane", "unload-truck", "unload-airplane", "drive-truck")
OPERATORS += ("fly-airplane",)
KINDS = {"obj": "package", "truck": "truck", "airplane": "airplane", "location": "location"}
KINDS |= {"city": "city"}  # type predicate -> kind (AIRPORT marks some locations)


@dataclass(frozen=True)
class LogisticsData:
    """The static facts of a logistics problem (hashable; ``Problem.data``)."""

    packages: tuple[str, ...]
    trucks: tuple[str, ...]
    airplanes: tuple[str, ...]
    cities: tuple[str, ...]
    city: tuple[str, ...]  # the city of each location, in ``Problem.fixed`` order
    airports: tuple[str, ...]
    truck_city: tuple[str, ...]  # the city of each truck (where it starts; it never leaves)

    def kind(self, name: str) -> str:
        """'package', 'truck', 'airplane' or 'other' (a location or a city)."""
        for kind, names in (("package", self.packages), ("truck", self.trucks)):
            if name in names:
                return kind
        return "airplane" if name in self.airplanes else "other"


def entity(problem: Problem, x: str) -> int:
    """The row of package or vehicle ``x``; ProblemError listing them if unknown."""
    if x not in problem.entities:
        raise ProblemError(f"unknown package or vehicle {one_of(x, problem.entities)}")
    return problem.entities.index(x)


def where(problem: Problem, state: Sequence[str], x: str) -> str:
    """The location of entity ``x`` (a package in a vehicle is where the vehicle is)."""
    s = state[entity(problem, x)]
    return s if s in problem.fixed else state[problem.entities.index(s)]


def reach(problem: Problem, v: str) -> list[int]:
    """The locations (indices) vehicle ``v`` may go to: its city's, or the airports."""
    d: LogisticsData = problem.data
    if d.kind(v) == "truck":
        return [j for j, c in enumerate(d.city) if c == d.truck_city[d.trucks.index(v)]]
    return [j for j, x in enumerate(problem.fixed) if x in d.airports]


Legs = tuple[tuple[str, int], ...]  # a route: (vehicle kind, start location) per leg


@functools.lru_cache(maxsize=4096)
def routes(data: LogisticsData, locations: tuple[str, ...]):
    """Shortest static package routes: ``(dist, legs)`` with ``dist[i][j]`` the legs from
    location i to j (inf: unreachable) and ``legs[i][j]`` one such route. A leg is a load, a
    vehicle move and an unload: by a truck within its city, or by an airplane between airports."""
    k, towns = len(locations), set(data.truck_city)
    port = [x in data.airports for x in locations]
    edge: list[list[str | None]] = [[None] * k for _ in range(k)]
    for i, j in itertools.permutations(range(k), 2):
        if data.city[i] == data.city[j] and data.city[i] in towns:
            edge[i][j] = "truck"
        elif port[i] and port[j] and data.airplanes:
            edge[i][j] = "airplane"
    dist = [
        [0.0 if i == j else 1.0 if edge[i][j] else math.inf for j in range(k)] for i in range(k)
    ]
    nxt = [[j if edge[i][j] else None for j in range(k)] for i in range(k)]
    for m, i, j in itertools.product(range(k), repeat=3):  # Floyd-Warshall
        if dist[i][m] + dist[m][j] < dist[i][j]:
            dist[i][j], nxt[i][j] = dist[i][m] + dist[m][j], nxt[i][m]

    def legs(i: int, j: int) -> Legs:
        out = []
        while i != j and nxt[i][j] is not None:
            out.append((edge[i][nxt[i][j]], i))
            i = nxt[i][j]
        return tuple(out)

    return tuple(map(tuple, dist)), tuple(tuple(legs(i, j) for j in range(k)) for i in range(k))


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


def from_pddl(domain: Domain, problem: PDDLProblem, order: Sequence[str] | None = None) -> Problem:
    """The relational `Problem` of a parsed logistics-strips problem.

    ``order``: the objects in file order (`pddl_io.object_order`); without it they are sorted
    naturally. PDDLError names what does not fit (an object without one type, a package in two
    places, an airplane off an airport, a goal that is not an ``at`` atom or cannot hold)."""
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


def random_problem(cities: int, locations: int, packages: int, planes: int, seed: int) -> Problem:
    """A random problem: one truck per city, ``locations`` per city (the first an airport),
    airplanes at random airports, packages and their goals at random locations (at least one
    package away from its goal)."""
    rng = random.Random(seed)
    cs = [f"c{i}" for i in range(cities)]
    city = {f"l{i}-{j}": c for i, c in enumerate(cs) for j in range(locations)}
    locs, ports = list(city), [f"l{i}-0" for i in range(cities)]
    support = {f"t{i}": f"l{i}-{rng.randrange(locations)}" for i in range(cities)}
    support |= {f"a{i}": rng.choice(ports) for i in range(planes)}
    support |= {f"p{i}": rng.choice(locs) for i in range(packages)}
    goal = [(f"p{i}", rng.choice(locs)) for i in range(packages)]
    if all(support[p] == g for p, g in goal):
        goal[0] = ("p0", rng.choice([x for x in locs if x != support["p0"]]))
    kinds = {c: "city" for c in cs} | {x: "location" for x in locs}
    kinds |= {x: {"t": "truck", "a": "airplane", "p": "package"}[x[0]] for x in support}
    order = [*(f"a{i}" for i in range(planes)), *cs, *(f"t{i}" for i in range(cities)), *locs]
    order += [f"p{i}" for i in range(packages)]
    name = f"logistics-c{cities}-s{locations}-p{packages}-a{planes}-{seed}"
    return make_problem(name, kinds, city, ports, support, goal, order)


SIZES = ((2, 1, 1, 1), (2, 2, 2, 1), (3, 1, 2, 2), (3, 2, 3, 2))  # cities, locations, ...


def samples(seed: int):
    """Random problems of 2-3 cities, 1-2 locations per city, 1-3 packages, 1-2 airplanes."""
    for cities, locations, packages, planes in SIZES:
        yield random_problem(cities, locations, packages, planes, seed)
