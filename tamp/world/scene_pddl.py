"""A scene as the problem of a user's pick-and-place PDDL domain, read from its geometry.

A domain bound to the motion layer (`task.symbolic.pickplace.binding`) whose binding has a
``scene`` section runs on any scene file (``tamp run --scene FILE --domain D.pddl --binding
B.json --goal G``). `problem_text` writes its PDDL problem: the scene's movable objects and
regions as the declared types, the initial state read from the geometry as a robot would read
it (`tamp.world.relations.read_facts`: ``on``, ``in``, ``ontable``, ``clear``; ``empty``: a
region no object stands in; ``narrower``: one object's footprint narrower than another's;
``fits``: an object's footprint inside a region's rectangle; ``handempty``), each relation
written with the predicate the binding names, and the goal's atoms (``(on a b)``, ``(in a
tray)``, ...) written the same way. A relation the binding does not write is left out, unless
it is where an object rests or a goal atom needs it: then a one-line ProblemError says so (the
domain could not know where that object is).
"""

from __future__ import annotations

from tamp.world.goal import Goal
from tamp.world.relations import read_facts
from tamp.world.schema import Scene
from task.errors import ProblemError
from task.problem import TABLE
from task.symbolic.pickplace.binding import Binding


def _fits(scene: Scene, name: str, region) -> bool:
    """Whether object ``name``'s footprint, turned any way, fits inside ``region``'s walls."""
    width = scene.object(name).width
    lo, hi = region.inner()
    return all(b - a >= width for a, b in zip(lo, hi, strict=True))


def _atoms(scene: Scene, binding: Binding) -> list[tuple[str, ...]]:
    """The initial state's atoms in the geometry's relations (before naming them)."""
    facts = read_facts(scene)
    if facts.unexplained:
        raise ProblemError(f"{binding.domain}: {facts.issues[0]}")
    objects = [o.name for o in scene.objects]
    regions = [r.name for r in scene.regions]
    holding = {s for _, s in facts.supports if s in regions}
    atoms = sorted(facts.atoms)
    atoms += [("empty", r) for r in regions if r not in holding]
    atoms += [
        ("narrower", x, y)
        for x in objects
        for y in objects
        if scene.object(x).width < scene.object(y).width
    ]
    atoms += [("fits", x, r.name) for x in objects for r in scene.regions if _fits(scene, x, r)]
    atoms.append(("handempty",))
    for name, support in facts.supports:
        relation = "ontable" if support == TABLE else "in" if support in regions else "on"
        if binding.scene.predicate(relation) is None:
            raise ProblemError(
                f"{binding.domain}: object {name} rests {relation} {support}, a relation the "
                f"binding's scene facts do not write (facts: {_written(binding)})"
            )
    return atoms


def _written(binding: Binding) -> str:
    return ", ".join(relation for relation, _ in binding.scene.facts)


def _named(atom: tuple[str, ...], binding: Binding) -> str | None:
    predicate = binding.scene.predicate(atom[0])
    return None if predicate is None else f"({' '.join((predicate, *atom[1:]))})"


def problem_text(scene: Scene, goal: Goal, binding: Binding) -> str:
    """The PDDL problem of ``scene`` toward ``goal`` in ``binding``'s domain (the module
    docstring); ProblemError when the binding has no scene section, the geometry does not
    explain an object, or an object's support or a goal atom is a relation it does not write."""
    if binding.scene is None:
        raise ProblemError(
            f"{binding.domain}: the binding has no scene section, so a scene cannot be read as "
            'its state (add "scene": {"facts": {...}}; see task.symbolic.pickplace.binding)'
        )
    init = [text for a in _atoms(scene, binding) if (text := _named(a, binding)) is not None]
    goals = []
    for atom in goal.atoms:
        text = _named(atom, binding)
        if text is None:
            raise ProblemError(
                f"{binding.domain}: goal ({' '.join(atom)}): the binding's scene facts do not "
                f"write {atom[0]} (facts: {_written(binding)})"
            )
        goals.append(text)
    objects = " ".join(o.name for o in scene.objects)
    regions = " ".join(r.name for r in scene.regions)
    if binding.scene.objects:
        objects += f" - {binding.scene.objects}"
    if regions and binding.scene.regions:
        regions += f" - {binding.scene.regions}"
    lines = [
        f"(define (problem {scene.name}) (:domain {binding.domain})",
        f"  (:objects {objects} {regions})",
        "  (:init",
        *(f"    {a}" for a in init),
        "  )",
        f"  (:goal (and {' '.join(goals)})))",
    ]
    return "\n".join(lines) + "\n"
