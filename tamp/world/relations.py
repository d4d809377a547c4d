"""The symbolic state of a scene, read from its geometry as a robot would read it.

Every object gets exactly one support fact from where it rests (`tamp.world.geometry.support`):

- ``(in x r)`` when x rests on region r's surface with its whole footprint inside the
  rectangle (inside the walls, when r has walls); nested regions give one fact each (an
  object in an alcove marked inside a larger area is in both), and its support is the
  innermost of them (`innermost`: the smallest), whatever order the file lists them in;
- ``(on x y)`` when x rests on object y alone;
- ``(ontable x)`` when x rests on the table (on a region's rectangle without being inside it
  counts as the table when the region is a marked area at table height);

and ``(clear x)`` holds when no object rests on x. ``in`` is direct: a block on a block in a
tray is ``on`` that block, not ``in`` the tray. An object whose support none of these explains
(on a tray's wall, on an obstacle's top, bridging two objects, on a tray's raised base but
reaching beyond it) gets no support fact; `Facts.unexplained` names it and `Facts.issues` says
why, one line each.
"""

from __future__ import annotations

from dataclasses import dataclass

from tamp.world.geometry import TABLE_FACE, TIGHT, Tolerances, inside, support
from tamp.world.schema import Scene
from task.problem import TABLE

Atom = tuple[str, ...]  # ("on", "a", "b"), as in `task.symbolic.strips`


@dataclass(frozen=True)
class Facts:
    """The crisp state read from a scene: ground atoms, each object's support (an object,
    a region or `task.problem.TABLE`; objects left unexplained have none), and the objects
    the geometry could not explain with the reasons."""

    atoms: frozenset[Atom]
    supports: tuple[tuple[str, str], ...]  # (object, support) in scene order
    unexplained: tuple[str, ...] = ()
    issues: tuple[str, ...] = ()

    def holds(self, atom: Atom) -> bool:
        return atom in self.atoms

    def text(self) -> str:
        """The atoms as PDDL, sorted, one per line (e.g. for a problem's ``(:init ...)``)."""
        return "\n".join(f"({' '.join(a)})" for a in sorted(self.atoms))


def read_facts(scene: Scene, tolerances: Tolerances = TIGHT) -> Facts:
    """The scene's ``on`` / ``in`` / ``ontable`` / ``clear`` facts (see the module docstring)."""
    names = {o.name for o in scene.objects}
    atoms: set[Atom] = set()
    supports, unexplained, issues = [], [], []
    below: set[str] = set()
    for o in scene.objects:
        rest = support(scene, o, tolerances)
        below |= {f for f in rest.faces if f in names}
        regions = [
            f.removeprefix("region:")
            for f in rest.faces
            if f.startswith("region:")
            and inside(scene.region(f.removeprefix("region:")), o, tolerances.edge)
        ]
        objects = [f for f in rest.faces if f in names]
        if regions:
            atoms |= {("in", o.name, r) for r in regions}
            supports.append((o.name, innermost(scene, regions)))
        elif len(objects) == 1 and len(rest.faces) == 1:
            atoms.add(("on", o.name, objects[0]))
            supports.append((o.name, objects[0]))
        elif TABLE_FACE in rest.faces and not objects and _flat(scene, rest.faces):
            atoms.add(("ontable", o.name))
            supports.append((o.name, TABLE))
        else:
            unexplained.append(o.name)
            issues.append(f"object {o.name} rests on {_faces(rest.faces)}: {_why(scene, rest)}")
    atoms |= {("clear", o.name) for o in scene.objects if o.name not in below}
    return Facts(frozenset(atoms), tuple(supports), tuple(unexplained), tuple(issues))


def innermost(scene: Scene, regions: list[str]) -> str:
    """Of the regions (names) an object stands in, the one that is its support: the smallest
    by area (a region nested in another is the smaller), ties to the first name in sorted
    order, so the file's order of its regions never decides."""

    def key(name: str) -> tuple[float, str]:
        r = scene.region(name)
        return (r.hi[0] - r.lo[0]) * (r.hi[1] - r.lo[1]), name

    return min(regions, key=key)


def _flat(scene: Scene, faces: tuple[str, ...]) -> bool:
    """True when every face besides the table is a region lying flat on it (no floor)."""
    for f in faces:
        if f == TABLE_FACE:
            continue
        if not f.startswith("region:"):
            return False
        r = scene.region(f.removeprefix("region:"))
        if r.on is not None or r.floor > 0:
            return False
    return True


def _faces(faces: tuple[str, ...]) -> str:
    return " and ".join(faces) if faces else "nothing"


def _why(scene: Scene, rest) -> str:
    if any(":wall_" in f for f in rest.faces):
        return "a region's wall is no support a plan can name"
    regions = [f for f in rest.faces if f.startswith("region:")]
    if regions:
        return "it reaches beyond the region's rectangle"
    if len([f for f in rest.faces if f in {o.name for o in scene.objects}]) > 1:
        return "it bridges two objects"
    return "an obstacle's top is no support a plan can name"
