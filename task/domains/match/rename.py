"""Seeded random renamings of a PDDL domain and its problems: what a renamed benchmark is.

`rename` gives every predicate, action, type, constant, variable and object a random name,
shuffles each action's parameter order and each predicate's argument order, and shuffles the
order of declarations (types, predicates, actions, atoms inside each list, ``:init`` atoms).
The problem files keep their names, their objects' order and their goals' order: the
hand-written domains read entities in file order and goals in goal order, so a planner that
breaks ties by them plans a renamed problem exactly as the original. Objects are renamed
monotonically (the i-th smallest name gets the i-th smallest new name) for the same reason;
``monotone=False`` draws them freely. The result carries the true `Renaming` (original ->
renamed) and the object names, to map plans back.
"""

from __future__ import annotations

import random
import shutil
import string
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from task.domains.match.renaming import Renamed, Renaming
from task.domains.match.schema import OBJECT, Schema, Shape, shape
from task.errors import PDDLError
from task.problem import Action
from task.symbolic import pddl_io, strips

_RESERVED = {"and", "not", "either", "object", "table", "robot", "define", "domain", "problem"}


@dataclass(frozen=True)
class RenamedFiles:
    """The renamed texts, the true renaming (reference: the original domain, user: the
    renamed one) and ``objects``: ``(original, renamed)`` object names."""

    domain: str
    problems: tuple[str, ...]
    renaming: Renaming
    objects: tuple[tuple[str, str], ...]

    def original(self, action: Action) -> Action:
        """A renamed ground action in the original names."""
        found = {r.user: r for r in self.renaming.actions}[action.name.lower()]
        back = {new: old for old, new in self.objects}
        back |= {new: old for old, new in self.renaming.constants}
        args = found.to_reference(tuple(a.lower() for a in action.args))
        return Action(found.reference, tuple(back.get(a, a) for a in args))

    def renamed(self, action: Action) -> Action:
        """An original ground action in the renamed names."""
        to = dict(self.objects) | dict(self.renaming.constants)
        moved = self.renaming.action(Action(action.name.lower(), tuple(action.args)))
        return Action(moved.name, tuple(to.get(a, a) for a in moved.args))


class _Words:
    """Fresh random lowercase names, never reserved words, never repeated."""

    def __init__(self, rng: random.Random):
        self.rng, self.used = rng, set(_RESERVED)

    def __call__(self) -> str:
        while True:
            word = "".join(self.rng.choice(string.ascii_lowercase) for _ in range(6))
            if word not in self.used:
                self.used.add(word)
                return word


@dataclass(frozen=True)
class _Names:
    """The new names of one renaming, drawn from ``rng`` (``words``: fresh names, for the
    variables still to be named): the domain's ``name``, its actions, predicates (each
    `Renamed`, with its argument order), types, constants and objects (original -> renamed),
    and whether the domain is ``typed`` (`_typed`)."""

    rng: random.Random
    words: _Words
    name: str
    acts: dict[str, Renamed]
    preds: dict[str, Renamed]
    types: dict[str, str]
    consts: dict[str, str]
    objects: dict[str, str]
    typed: bool


def _perm(rng: random.Random, k: int) -> tuple[int, ...]:
    order = list(range(k))
    rng.shuffle(order)
    return tuple(order)


def _atom(pattern: tuple, preds: dict[str, Renamed], names: Sequence[str], consts: dict) -> str:
    """A schema pattern as text: predicate renamed, arguments reordered, terms named."""
    terms = [f"?{names[t]}" if isinstance(t, int) else consts.get(t, t) for t in pattern[1:]]
    return "(" + " ".join((preds[pattern[0]].user, *preds[pattern[0]].to_user(terms))) + ")"


def _action(s: Schema, new: _Names) -> str:
    r, preds, types, consts, typed = new.acts[s.name], new.preds, new.types, new.consts, new.typed
    old_names = [new.words() for _ in s.params]  # the variable of original parameter i
    params = " ".join(
        f"?{old_names[i]}" + (f" - {types.get(s.types[i], s.types[i])}" if typed else "")
        for i in r.order
    )
    pre = [_atom(a, preds, old_names, consts) for a in s.pre]
    eff = [_atom(a, preds, old_names, consts) for a in s.add]
    eff += [f"(not {_atom(a, preds, old_names, consts)})" for a in s.delete]
    new.rng.shuffle(pre)
    new.rng.shuffle(eff)
    lines = [f"  (:action {r.user}", f"    :parameters ({params})"]
    if pre:
        lines.append(f"    :precondition (and {' '.join(pre)})")
    lines.append(f"    :effect (and {' '.join(eff)}))")
    return "\n".join(lines)


def _typed(dom: Shape) -> bool:
    """Whether the domain declares types (then every renamed parameter carries one)."""
    return any(t != OBJECT for t, _ in dom.parents) or any(
        t != OBJECT for s in dom.actions for t in s.types
    )


def _domain_text(dom: Shape, new: _Names) -> str:
    types, consts, preds, typed = new.types, new.consts, new.preds, new.typed
    lines = [
        f"(define (domain {new.name})",
        f"  (:requirements :strips{' :typing' if typed else ''})",
    ]
    if typed:
        decl = [
            f"{types[t]}" + (f" - {types.get(p, p)}" if p not in (None, OBJECT) else "")
            for t, p in dom.parents
            if t != OBJECT
        ]
        new.rng.shuffle(decl)
        lines.append(f"  (:types {' '.join(decl)})")
    if dom.constants:
        decl = [f"{consts[c]}" + (f" - {types[k]}" if typed else "") for c, k in dom.constants]
        lines.append(f"  (:constants {' '.join(decl)})")
    declared = []
    for pred, arg_types in dom.predicates:
        vars_ = [f"?{new.words()}" + (f" - {types.get(t, t)}" if typed else "") for t in arg_types]
        declared.append(f"({' '.join((preds[pred].user, *preds[pred].to_user(vars_)))})")
    new.rng.shuffle(declared)
    lines.append(f"  (:predicates {' '.join(declared)})")
    actions = [_action(s, new) for s in dom.actions]
    new.rng.shuffle(actions)
    return "\n".join([*lines, *actions, ")"]) + "\n"


def _problem_text(text: str, domain, new: _Names) -> str:
    preds, types, objects, typed = new.preds, new.types, new.objects, new.typed
    parsed = pddl_io.parse_problem(text, "<problem>", domain)
    kinds = {
        str(o.name).lower(): sorted(str(t).lower() for t in o.type_tags) for o in parsed.objects
    }
    declared = []
    for x in pddl_io.object_order(text):
        kind = kinds[x][0] if kinds[x] else OBJECT
        declared.append(objects[x] + (f" - {types.get(kind, kind)}" if typed else ""))

    def atom(a: tuple) -> str:
        r = preds[a[0]]
        return strips.atom_str((r.user, *r.to_user([objects.get(x, x) for x in a[1:]])))

    init = [atom(a) for a in sorted(strips.initial_state(parsed))]
    new.rng.shuffle(init)
    goal = [atom(a) for a in strips.goal_atoms(parsed)]
    lines = [f"(define (problem {str(parsed.name).lower()})", f"  (:domain {new.name})"]
    lines += [f"  (:objects {' '.join(declared)})", "  (:init", *(f"    {a}" for a in init), "  )"]
    lines += ["  (:goal (and", *(f"    {a}" for a in goal), "  ))", ")"]
    return "\n".join(lines) + "\n"


def _object_names(texts: Sequence[str], domain, words, monotone: bool) -> dict[str, str]:
    old = sorted({x for t in texts for x in pddl_io.object_order(t)})
    new = [words() for _ in old]
    if monotone:
        new.sort()
    return dict(zip(old, new, strict=True))


def rename(
    domain_text: str, problem_texts: Sequence[str] = (), seed: int = 0, monotone: bool = True
) -> RenamedFiles:
    """A seeded random renaming of a STRIPS domain and its problems (see the module doc).
    PDDLError for a domain the matcher could not read either (`schema.shape`)."""
    domain = pddl_io.parse_domain(domain_text, "<domain>")
    dom = shape(domain)
    if isinstance(dom, str):
        raise PDDLError(f"cannot rename: {dom}")
    rng = random.Random(seed)
    words = _Words(rng)
    words.used |= {x for t in problem_texts for x in pddl_io.object_order(t)}
    name = words()
    acts = {s.name: Renamed(s.name, words(), _perm(rng, len(s.params))) for s in dom.actions}
    preds = {p: Renamed(p, words(), _perm(rng, len(ts))) for p, ts in dom.predicates}
    types = {t: words() for t, _ in dom.parents if t != OBJECT}
    consts = {c: words() for c, _ in dom.constants}
    objects = _object_names(problem_texts, domain, words, monotone)
    new = _Names(
        rng=rng,
        words=words,
        name=name,
        acts=acts,
        preds=preds,
        types=types,
        consts=consts,
        objects=objects,
        typed=_typed(dom),
    )
    text = _domain_text(dom, new)
    problems = tuple(_problem_text(t, domain, new) for t in problem_texts)
    renaming = Renaming(
        dom.name,
        name,
        tuple(sorted(acts.values(), key=lambda r: r.reference)),
        tuple(sorted(preds.values(), key=lambda r: r.reference)),
        tuple(sorted(types.items())),
        tuple(sorted(consts.items())),
    )
    return RenamedFiles(text, problems, renaming, tuple(sorted(objects.items())))


def rename_folder(source: str | Path, out: str | Path, seed: int = 0) -> RenamedFiles:
    """A renamed copy of a benchmark folder: ``source/domain.pddl`` and every
    ``source/instances/**/*.pddl`` renamed by one seeded `rename`, written under ``out`` with
    the same file names (``manifest.csv`` and ``info.json`` copied as they are), so
    ``tamp bench planbench --data OUT`` runs the renamed set. Run as
    ``python -m task.domains.match.rename SOURCE OUT [SEED]``."""
    src, dst = Path(source), Path(out)
    if not (src / "domain.pddl").is_file():
        raise PDDLError(f"{src}: no domain.pddl (a benchmark folder: domain.pddl, instances/)")
    paths = sorted(src.glob("instances/**/*.pddl"))
    renamed = rename((src / "domain.pddl").read_text(), [p.read_text() for p in paths], seed)
    dst.mkdir(parents=True, exist_ok=True)
    (dst / "domain.pddl").write_text(renamed.domain)
    for path, text in zip(paths, renamed.problems, strict=True):
        target = dst / path.relative_to(src)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text)
    for name in ("manifest.csv", "info.json"):
        if (src / name).is_file():
            shutil.copy(src / name, dst / name)
    return renamed


if __name__ == "__main__":
    import sys

    if len(sys.argv) not in (3, 4):
        sys.exit("usage: python -m task.domains.match.rename SOURCE OUT [SEED]")
    made = rename_folder(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) == 4 else 0)
    print(f"{len(made.problems)} problems renamed into {sys.argv[2]}")
