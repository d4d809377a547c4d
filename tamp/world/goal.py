"""A symbolic goal over a scene's objects and regions, from PDDL goal text.

A goal is one atom or a conjunction, ``(on a b)`` or ``(and (on a b) (in c tray))``, given
inline or in a file (the file may hold the bare formula or a PDDL problem, whose
``(:goal ...)`` is taken). The predicates are those `tamp.world.relations` reads:
``(on object object)``, ``(in object region)``, ``(ontable object)``, ``(clear object)``.
Names are lowercased (PDDL is case-insensitive). Every name is checked against the scene: an
unknown object or region, an unknown predicate, a wrong number of arguments or a region where
an object belongs is one `SceneFileError` line that lists what is valid.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from tamp.world.relations import Atom, Facts
from tamp.world.schema import Scene, SceneFileError
from task.errors import one_of

# predicate -> the kind of each argument
PREDICATES: dict[str, tuple[str, ...]] = {
    "on": ("object", "object"),
    "in": ("object", "region"),
    "ontable": ("object",),
    "clear": ("object",),
}
TOKEN = re.compile(r"\(|\)|[^\s()]+")


@dataclass(frozen=True)
class Goal:
    """A conjunction of ground atoms over a scene."""

    atoms: tuple[Atom, ...]

    def unmet(self, facts: Facts) -> tuple[Atom, ...]:
        """The goal atoms ``facts`` do not hold."""
        return tuple(a for a in self.atoms if a not in facts.atoms)

    def holds(self, facts: Facts) -> bool:
        return not self.unmet(facts)

    def text(self) -> str:
        return "(and " + " ".join(f"({' '.join(a)})" for a in self.atoms) + ")"


def load_goal(spec: str | Path, scene: Scene) -> Goal:
    """The goal ``spec``: inline PDDL when it starts with ``(``, else the path of a file."""
    if isinstance(spec, str) and spec.lstrip().startswith("("):
        return parse_goal(spec, scene)
    path = Path(spec)
    if isinstance(spec, str) and not path.exists() and " " in spec.strip():
        raise SceneFileError(
            f"goal {spec!r}: a goal is a parenthesised PDDL formula, e.g. '({spec.strip()})', "
            "or the path of a goal file"
        )
    try:
        text = path.read_text()
    except OSError as exc:
        raise SceneFileError(f"goal file {path}: cannot read it ({exc.strerror})") from None
    return parse_goal(text, scene, source=f"goal file {path}")


def parse_goal(text: str, scene: Scene, source: str = "goal") -> Goal:
    """The goal in PDDL ``text``, checked against ``scene``'s objects and regions."""
    tokens = TOKEN.findall(re.sub(r";[^\n]*", "", text).lower())
    start = next((i for i in range(len(tokens) - 1) if tokens[i : i + 2] == ["(", ":goal"]), None)
    if start is not None:  # a PDDL problem: its (:goal ...) section
        tree, _ = _read(tokens, start + 2, source)
    else:
        tree, end = _read(tokens, 0, source)
        if end != len(tokens):
            raise SceneFileError(f"{source}: text after the goal: {' '.join(tokens[end:])!r}")
    if isinstance(tree, str):
        raise SceneFileError(f"{source}: expected an atom such as (on a b), got {tree!r}")
    items = tree[1:] if tree and tree[0] == "and" else [tree]
    atoms = tuple(_atom(item, scene, source) for item in items)
    if not atoms:
        raise SceneFileError(f"{source}: the goal is empty")
    return Goal(atoms)


def _read(tokens: list[str], i: int, source: str):
    """One s-expression from ``tokens[i]``: (tree, index after it)."""
    if i >= len(tokens):
        raise SceneFileError(f"{source}: unbalanced parentheses (the goal ends early)")
    if tokens[i] == ")":
        raise SceneFileError(f"{source}: unbalanced parentheses (a ')' too many)")
    if tokens[i] != "(":
        return tokens[i], i + 1
    out, i = [], i + 1
    while i < len(tokens) and tokens[i] != ")":
        item, i = _read(tokens, i, source)
        out.append(item)
    if i >= len(tokens):
        raise SceneFileError(f"{source}: unbalanced parentheses (a ')' is missing)")
    return out, i + 1


def _show(tree) -> str:
    if isinstance(tree, str):
        return tree
    return "(" + " ".join(_show(t) for t in tree) + ")"


def _atom(tree, scene: Scene, source: str) -> Atom:
    where = f"{source}: {_show(tree)}"
    if isinstance(tree, str) or not tree or not all(isinstance(t, str) for t in tree):
        raise SceneFileError(
            f"{where}: a goal is an atom or (and atom ...) of atoms such as (on a b); "
            "not, or, nested and and quantifiers are not supported"
        )
    pred, *args = tree
    if pred not in PREDICATES:
        raise SceneFileError(f"{where}: unknown predicate {one_of(pred, sorted(PREDICATES))}")
    kinds = PREDICATES[pred]
    if len(args) != len(kinds):
        raise SceneFileError(
            f"{where}: {pred} takes {len(kinds)} argument(s) ({' '.join(kinds)}), got {len(args)}"
        )
    objects = [o.name for o in scene.objects]
    regions = [r.name for r in scene.regions]
    for arg, kind in zip(args, kinds, strict=True):
        valid, other = (objects, regions) if kind == "object" else (regions, objects)
        if arg in valid:
            continue
        if arg in other:
            other_kind = "a region" if kind == "object" else "an object"
            raise SceneFileError(
                f"{where}: {arg!r} is {other_kind}, {pred} takes ({' '.join(kinds)}); "
                f"{kind}s: {', '.join(valid) or 'none'}"
            )
        raise SceneFileError(f"{where}: unknown {kind} {one_of(arg, valid)}")
    if pred == "on" and args[0] == args[1]:
        raise SceneFileError(f"{where}: an object cannot be on itself")
    return (pred, *args)
