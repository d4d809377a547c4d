"""The memory of the moves the arm failed, for motion-aware planning (`tamp.arm.costs.ArmCosts`):
a move kept by where it failed (`FailedMove`: its pick and place `Site`s, ruled out in any
state where they are the same again) and a move kept by the state it failed in (`failed_key`,
the ``avoid`` of `tamp.arm.arm.Arm`, and `column`, its action column in a problem).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from tamp.scene import PlacedMove, Pose
from task.problem import TABLE, Problem

# reach of the hand and the forearm over it (the next slot, not the diagonal one); how far a
# block may be from where it was recorded to still count as there (observation noise)
AROUND, SAME = 0.2, 0.015


@dataclass(frozen=True)
class Site:
    """A point of a move (where the hand picks a block, or where it would put one) with the
    blocks then within `AROUND` of it in (x, y): what a grasp or release there runs into."""

    xyz: tuple[float, float, float]
    around: tuple[tuple[str, tuple[float, float, float]], ...]  # (name, centre), by name

    @classmethod
    def at(cls, xyz, poses: Mapping[str, Pose], leave: str) -> Site:
        """The site of point ``xyz`` among the blocks at ``poses`` (name -> `Pose`) but
        ``leave`` (the block that moves)."""
        point = tuple(float(v) for v in xyz)
        around = tuple(
            (name, tuple(float(v) for v in p.xyz))
            for name, p in sorted(poses.items())
            if name != leave and math.dist(p.xyz[:2], point[:2]) <= AROUND
        )
        return cls(point, around)

    def matches(self, xyz, poses: Mapping[str, Pose], leave: str) -> bool:
        """Whether point ``xyz`` among ``poses`` is this site again, or one at least as
        crowded: the point and every block that was around it where they were (within
        `SAME`); a block come near since only adds to what the hand runs into."""
        if math.dist(xyz, self.xyz) > SAME:
            return False
        return all(
            name in poses and math.dist(poses[name].xyz, at) <= SAME for name, at in self.around
        )


@dataclass(frozen=True)
class FailedMove:
    """A move the arm failed, kept by where it failed (`ArmCosts`' ``failed``): moving
    ``entity`` from the ``pick`` site to the ``place`` site, or from the ``pick`` site to
    anywhere (``place`` None: the pick itself failed with every grasp, whatever the place).
    It is ruled out wherever both sites are the same again (or more crowded) and the stacks
    as high, in any state: the memory of the move in the state it failed in (``avoid``) holds
    in that state only."""

    entity: str
    pick: Site
    place: Site | None
    top: float  # m: the highest block's centre then (the top-down hand hovers over it)

    @classmethod
    def of(cls, entity: str, poses: Mapping[str, Pose], place, pick_only: bool) -> FailedMove:
        """``entity`` (at ``poses[entity]``) failed to move to the point ``place`` (its
        centre there), or to be picked at all (``pick_only``)."""
        pick = Site.at(poses[entity].xyz, poses, entity)
        place = None if pick_only else Site.at(place, poses, entity)
        return cls(entity, pick, place, max(float(p.xyz[2]) for p in poses.values()))

    def columns(self, entities: Sequence[str], now: Mapping[str, Pose], places) -> list[int]:
        """The action columns this failure rules out in a state whose blocks stand at ``now``,
        its targets' points ``places`` (Y, 3): none unless the block is picked where it
        failed, with the highest stack as high or higher."""
        at = now.get(self.entity)
        if at is None or not self.pick.matches(at.xyz, now, self.entity):
            return []
        if max(float(p.xyz[2]) for p in now.values()) < self.top - SAME:
            return []  # the hand hovers lower now
        if self.place is None:
            return list(range(len(places)))
        e = entities.index(self.entity)
        return [
            j
            for j, point in enumerate(places)
            if j != e and self.place.matches(point, now, self.entity)
        ]


def failed_key(move) -> tuple[str, object]:
    """``(entity, target)`` of a move for `ArmCosts`' ``avoid``: a block name, "table", or
    ("at", place, x, y) for a move onto a planned table place (`tamp.scene.PlacedMove`: the
    place's name and the position the block was to go to, to the mm)."""
    if isinstance(move, PlacedMove) and move.at is not None:
        at = move.at
        return move.entity, ("at", move.place, round(at[0], 3), round(at[1], 3))
    return move.entity, move.target


def column(problem: Problem, key, at, reach: float) -> int | None:
    """The action column of a `failed_key` target in ``problem`` (None when the problem has no
    such target). A place matches by name (any place when the key names none) and by
    position: the failed position lies within the place's ``reach`` (each offset is at most
    ``reach`` in x and y) of its centre, to the key's mm; the nearest such place."""
    if isinstance(key, str) and key != TABLE:
        return problem.entities.index(key)
    if at is None:  # the one table column
        return problem.n
    if isinstance(key, str):
        return None  # "somewhere on the table": no one place to blame
    _, place, x, y = key
    tol = reach * math.sqrt(2) + 1e-3
    near = [
        (math.dist(at[k], (x, y)), j)
        for j, k in enumerate(problem.fixed)
        if place in (None, k) and math.dist(at[k], (x, y)) <= tol
    ]
    return problem.n + min(near)[1] if near else None
