"""Logistics' static map: the facts of a problem that never change, and routes over them.

`LogisticsData` (``Problem.data``) holds the packages, trucks, airplanes and cities, the city
of every location, the airports and each truck's city. On a crisp state (the support of every
entity: a location, or for a package the vehicle it is in) `entity` finds an entity's row,
`where` its location and `reach` the locations a vehicle may go to; `routes` gives the
shortest static package routes between locations, the legs the domain's bound and potential
count.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from task.errors import ProblemError, one_of
from task.problem import Problem


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
