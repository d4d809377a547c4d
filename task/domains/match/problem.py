"""A user's problem read as the hand-written domain's: `to_reference`.

Objects keep their names (and their order); each object's type, and every init and goal atom,
goes through the `Renaming` back to the reference's names. Atoms of predicates that no action
mentions are inert: in ``:init`` they are dropped, in ``:goal`` they must already hold (else the
goal is unsolvable, a PDDLError). The reference problem is written as PDDL text and parsed
against the reference domain, so the hand-written ``from_pddl`` reads it as it reads its own
files.
"""

from __future__ import annotations

from collections.abc import Sequence

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.domains.match.recognise import Match, reference_domain
from task.domains.match.renaming import Renaming
from task.errors import PDDLError
from task.symbolic import pddl_io, strips


def _kind(tags) -> str:
    names = sorted(str(t).lower() for t in tags)
    return names[0] if names else "object"


def _objects(renaming: Renaming, domain: Domain, problem: PDDLProblem) -> list[tuple[str, str]]:
    """``(object, reference type)`` of every object and unmapped constant, in file order of
    ``problem.objects`` (sorted, as `pddl` keeps a set) then constants."""
    mapped = {u for _, u in renaming.constants}
    found = [(str(o.name).lower(), _kind(o.type_tags)) for o in problem.objects]
    found += [
        (str(c.name).lower(), _kind(c.type_tags))
        for c in domain.constants
        if str(c.name).lower() not in mapped
    ]
    typed = bool(renaming.types) and any(r != "object" for r, _ in renaming.types)
    out = []
    for name, kind in sorted(found):
        ref = renaming.reference_type(kind)
        if ref is None and typed:
            users = ", ".join(u for _, u in renaming.types)
            raise PDDLError(f"object {name} has type {kind}, which no action takes ({users})")
        out.append((name, ref or "object"))
    return out


def _goal(renaming: Renaming, problem: PDDLProblem, init: frozenset) -> list[tuple[str, ...]]:
    out = []
    for atom in strips.goal_atoms(problem):
        ref = renaming.to_reference(atom)
        if ref is not None:
            out.append(ref)
        elif atom not in init:
            raise PDDLError(
                f"unsolvable goal: {strips.atom_str(atom)} does not hold at the start and no "
                f"action of {renaming.domain} adds it"
            )
    return out


def to_reference(
    found: Match, domain: Domain, problem: PDDLProblem, order: Sequence[str] | None
) -> tuple[Domain, PDDLProblem, tuple[str, ...] | None]:
    """``(reference domain, reference problem, object order)`` of the user's ``problem`` of
    ``domain``, which ``found`` matched (``order``: its objects in file order,
    `pddl_io.object_order`; unmapped constants follow)."""
    renaming = found.renaming
    objects = _objects(renaming, domain, problem)
    init = strips.initial_state(problem)
    atoms = [a for a in (renaming.to_reference(x) for x in sorted(init)) if a is not None]
    goal = _goal(renaming, problem, init)
    rules_domain = reference_domain(found.rules)
    spelled = {str(t).lower(): str(t) for t in rules_domain.types}  # the file's own case
    typed = any(kind != "object" for _, kind in objects)
    declared = " ".join(f"{x} - {spelled.get(k, k)}" if typed else x for x, k in objects)
    lines = [f"(define (problem {str(problem.name).lower()})", f"(:domain {renaming.reference})"]
    lines += [f"(:objects {declared})", "(:init"]
    lines += [f"  {strips.atom_str(a)}" for a in atoms]
    lines += [")", "(:goal (and", *(f"  {strips.atom_str(a)}" for a in goal), "))", ")"]
    parsed = pddl_io.parse_problem("\n".join(lines) + "\n", str(problem.name), rules_domain)
    if order is None:
        return rules_domain, parsed, None
    names = {x for x, _ in objects}
    extra = tuple(x for x, _ in objects if x not in order)
    return rules_domain, parsed, tuple(x for x in order if x in names) + extra
