"""The values the geometric TAMP room shares: placements, moves, plans and their status.

A world state is a `tamp.world.schema.Scene` whose objects carry their current poses (scenes
are frozen; `moved` gives the scene after a move). Its symbolic state is read from the geometry
with `tamp.world.relations.read_facts`, never given.

`GeoLimits` are an episode's limits (`tamp.geo.episode.run_geo_episode`): moves run, plans after
the first and each planner call's wall clock; ``tamp run``, ``tamp bench tamp`` and
`tamp.api.run` run with its defaults.

A `Place` is where an object's centre goes: on top of another object, in a region, or on the
table, with its yaw. A `GeoMove` is one pick-and-place: the object, the grasp the hand holds it
by (`motion.grasps.Grasp`; None when the planner leaves the choice to the executor) and the
place. A planner returns a `GeoPlan`: a status, the moves, a one-line reason when it did not
solve the problem, and its statistics.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from tamp.scene import Pose
from tamp.world.schema import Scene
from task.problem import TABLE

if TYPE_CHECKING:
    from motion.grasps import Grasp

__all__ = ["TABLE", "GeoLimits", "GeoMove", "GeoPlan", "GeoStatus", "Place", "moved"]


@dataclass(frozen=True)
class GeoLimits:
    """A geometric episode's limits: ``max_moves`` moves run (Tower of Hanoi with 5 discs takes
    31 at best), ``max_replans`` plans after the first, and ``planning_s`` each planner call's
    wall clock (s, `tamp.geo.search.SearchConfig.max_time_s`)."""

    max_moves: int = 40
    max_replans: int = 3
    planning_s: float = 120.0


@dataclass(frozen=True)
class Place:
    """Where an object goes: its ``target`` (an object's name, a region's name, or
    `task.problem.TABLE`), the object's centre after placing (``xyz``, m, base frame) and its
    yaw (rad). ``name`` tells discretised places apart (e.g. ``"tray.c2"``, ``"table.s4"``,
    ``"on.b"``); two places with the same name are the same choice."""

    name: str
    target: str
    xyz: tuple[float, float, float]
    yaw: float = 0.0

    @property
    def pose(self) -> Pose:
        return Pose(self.xyz, self.yaw)


@dataclass(frozen=True)
class GeoMove:
    """One pick-and-place: ``obj`` is picked with ``grasp`` and its centre put at ``place``."""

    obj: str
    place: Place
    grasp: Grasp | None = None

    def text(self) -> str:
        how = "" if self.grasp is None else f" [{self.grasp.name}]"
        x, y, _ = self.place.xyz
        return f"move {self.obj} -> {self.place.target} at ({x:.3f}, {y:.3f}){how}"

    def __str__(self) -> str:
        return self.text()


class GeoStatus(enum.Enum):
    """How a planner ended: SOLVED; UNSOLVABLE (no plan exists within the discretised grasp and
    placement choices: the search was exhaustive); BUDGET (node, sample or time budget spent
    first); FAILED (the planner gave up for another reason, named in the reason)."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    BUDGET = "budget"
    FAILED = "failed"


@dataclass(frozen=True)
class GeoPlan:
    """A planner's answer: ``moves`` in order (empty unless SOLVED), a one-line ``reason`` when
    not solved, and ``stats`` (planning time in s, nodes, motion checks, failures, ...)."""

    status: GeoStatus
    moves: tuple[GeoMove, ...] = ()
    reason: str = ""
    stats: dict = field(default_factory=dict)

    @property
    def solved(self) -> bool:
        return self.status is GeoStatus.SOLVED


def moved(scene: Scene, obj: str, pose: Pose) -> Scene:
    """The scene with object ``obj`` at ``pose`` (every other object where it was)."""
    scene.object(obj)  # an unknown name is one SceneFileError line listing the objects
    objects = tuple(replace(o, pose=pose) if o.name == obj else o for o in scene.objects)
    return replace(scene, objects=objects)
