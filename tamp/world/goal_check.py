"""The static check of a goal over a scene file: goals no plan can reach, found before planning.

`unsolvable_reason(scene, goal)` says why no sequence of moves can make the goal's atoms hold
at once, or None when it finds no such reason. It is sound, not complete: a goal it passes may
still have no plan (that is the planner's to find). The rules, each read from the goal and the
scene's sizes alone:

- the ``on`` / ``ontable`` atoms, by the same rule as a PDDL Blocksworld goal
  (`task.domains.blocksworld_pddl.support_error`): an object on two things, two things on one
  object (every planner here puts one object on another's top, centred), a cycle;
- an object on something and in a region, or on the table and in a region (one support);
- ``(clear y)`` with ``(on x y)``;
- an object in a region whose inner rectangle cannot hold its footprint however it is turned
  (its narrower side wider than the region's narrower side, or its wider side longer than the
  region's diagonal), or objects in one region whose footprints together cover more than it;
- an object in two regions at different heights, or whose rectangles do not nest and overlap
  too little to hold it.

Every reader of a goal over a scene file runs it through `check_goal` before any planning
(`tamp.world.blocks.scene_task`, `tamp.geo.scene_file.geo_run` and ``user_domain``), which
raises `UnsolvableGoal` (a `SceneFileError`) with the reason; ``tamp run`` reports that as the
``unsolvable`` outcome, as ``tamp plan`` does for a PDDL problem.
"""

from __future__ import annotations

import math
from collections import defaultdict

from tamp.world.goal import Goal
from tamp.world.schema import Movable, Region, Scene, SceneFileError
from task.domains.blocksworld_pddl import support_error
from task.problem import TABLE


class UnsolvableGoal(SceneFileError):
    """A goal over a scene file that no plan can reach; ``reason`` says why (one line)."""

    def __init__(self, reason: str):
        super().__init__(f"unsolvable goal: {reason}")
        self.reason = reason


def check_goal(scene: Scene, goal: Goal) -> Goal:
    """``goal`` when `unsolvable_reason` finds nothing against it, else `UnsolvableGoal`."""
    reason = unsolvable_reason(scene, goal)
    if reason is not None:
        raise UnsolvableGoal(reason)
    return goal


def unsolvable_reason(scene: Scene, goal: Goal) -> str | None:
    """Why ``goal`` cannot hold in ``scene`` whatever the moves (see the module docstring), or
    None."""
    pairs = [
        (a[1], a[2] if a[0] == "on" else TABLE) for a in goal.atoms if a[0] in ("on", "ontable")
    ]
    reason = support_error(pairs)
    if reason is not None:
        return reason
    regions: dict[str, list[str]] = defaultdict(list)  # object -> the regions it is to be in
    for atom in goal.atoms:
        if atom[0] == "in":
            regions[atom[1]].append(atom[2])
    support = dict(pairs)
    for x, names in regions.items():
        if x in support:
            what = "the table" if support[x] == TABLE else support[x]
            return f"{x} has two supports: {what}, region {names[0]}"
    for atom in goal.atoms:
        if atom[0] == "clear":
            above = [x for x, y in pairs if y == atom[1]]
            if above:
                return f"(clear {atom[1]}) with (on {above[0]} {atom[1]})"
    for x, names in regions.items():
        reason = _fit(scene.object(x), [scene.region(r) for r in names])
        if reason is not None:
            return reason
    return _crowded(scene, regions)


def _sides(lo: tuple[float, float], hi: tuple[float, float]) -> tuple[float, float]:
    """A rectangle's (narrower, wider) side, m (0 for an empty one)."""
    w, d = max(hi[0] - lo[0], 0.0), max(hi[1] - lo[1], 0.0)
    return min(w, d), max(w, d)


def _footprint(o: Movable) -> tuple[float, float]:
    """The object's footprint's (narrower, wider) side, m."""
    return 2.0 * min(o.half[0], o.half[1]), 2.0 * max(o.half[0], o.half[1])


def _area(o: Movable) -> float:
    """The object's footprint's area, m^2 (a cylinder's a disc)."""
    small, large = _footprint(o)
    return math.pi * small * small / 4.0 if o.kind == "cylinder" else small * large


def _holds(o: Movable, lo: tuple[float, float], hi: tuple[float, float]) -> bool:
    """False when the rectangle ``lo``-``hi`` cannot hold ``o``'s footprint at any yaw."""
    narrow, wide = _sides(lo, hi)
    small, large = _footprint(o)
    return small <= narrow + 1e-9 and large <= math.hypot(narrow, wide) + 1e-9


def _size(narrow: float, wide: float) -> str:
    return f"{narrow:g} x {wide:g} m"


def _fit(o: Movable, regions: list[Region]) -> str | None:
    """Why ``o`` cannot be in all of ``regions`` at once, or None."""
    for r in regions:
        if not _holds(o, *r.inner()):
            return (
                f"(in {o.name} {r.name}): {o.name}'s footprint {_size(*_footprint(o))} does not "
                f"fit {r.name}'s inner rectangle {_size(*_sides(*r.inner()))}"
            )
    for i, r in enumerate(regions):
        for s in regions[i + 1 :]:
            if abs(r.surface - s.surface) > 1e-6:
                return (
                    f"{o.name} in {r.name} and {s.name}: their surfaces are at different "
                    f"heights ({r.surface:g} m, {s.surface:g} m)"
                )
            (a0, a1), (b0, b1) = r.inner(), s.inner()
            lo = (max(a0[0], b0[0]), max(a0[1], b0[1]))
            hi = (min(a1[0], b1[0]), min(a1[1], b1[1]))
            if not _holds(o, lo, hi):
                return (
                    f"{o.name} in {r.name} and {s.name}: the regions do not nest and overlap "
                    f"too little to hold {o.name} ({_size(*_sides(lo, hi))} in common)"
                )
    return None


def _crowded(scene: Scene, regions: dict[str, list[str]]) -> str | None:
    """Why the objects to be in one region cannot all fit in it (their footprints' areas
    together exceed its inner rectangle's), or None."""
    members: dict[str, list[str]] = defaultdict(list)
    for x, names in regions.items():
        for r in names:
            members[r].append(x)
    for r, xs in members.items():
        narrow, wide = _sides(*scene.region(r).inner())
        need = sum(_area(scene.object(x)) for x in xs)
        if len(xs) > 1 and need > narrow * wide + 1e-12:
            return (
                f"{', '.join(xs)} in {r}: their footprints cover {need * 1e4:.0f} cm^2, "
                f"{r}'s inner rectangle {narrow * wide * 1e4:.0f} cm^2"
            )
    return None
