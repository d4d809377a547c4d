"""The names check of a parsed problem against its domain: predicates, arities, objects.

An ``:init`` or ``:goal`` atom with an unknown predicate, the wrong number of arguments or an
unknown object is bad input (a typo), not an unsolvable problem: one `PDDLError` line naming
the file and listing what would be valid.
"""

from __future__ import annotations

from collections.abc import Iterable

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem
from pddl.logic.predicates import Predicate
from pddl.logic.terms import Constant

from task.errors import PDDLError, one_of


def predicates_in(formula: object) -> Iterable[Predicate]:
    """Every atom of a formula (through and, or, not, imply, quantifiers), in file order."""
    if isinstance(formula, Predicate):
        yield formula
        return
    for part in getattr(formula, "operands", ()):
        yield from predicates_in(part)
    for name in ("argument", "condition"):
        if hasattr(formula, name):
            yield from predicates_in(getattr(formula, name))


def check_names(problem: PDDLProblem, domain: Domain, order: tuple[str, ...], source: str) -> None:
    """PDDLError (one line naming ``source``) for an ``:init`` or ``:goal`` atom whose predicate
    the domain lacks or takes another number of arguments, or that names an object neither in
    ``:objects`` nor a domain constant: a typo in the goal is bad input, not an unsolvable
    problem. Variables (under a quantifier) are not objects; ``order``: the objects in file order
    (`object_order`), as the valid ones are listed."""
    arity = {str(p.name).lower(): p.arity for p in domain.predicates}
    declared = [str(o.name).lower() for o in (*problem.objects, *domain.constants)]
    objects = list(dict.fromkeys([*order, *sorted(declared)]))
    init = [atom for fact in sorted(problem.init, key=str) for atom in predicates_in(fact)]
    for where, atoms in (("init", init), ("goal", list(predicates_in(problem.goal)))):
        for atom in atoms:
            name, terms = str(atom.name).lower(), list(atom.terms)
            text = "(" + " ".join([name, *(str(t.name).lower() for t in terms)]) + ")"
            if name not in arity:
                known = one_of(name, sorted(arity))
                raise PDDLError(f"{source}: {where} atom {text}: unknown predicate {known}")
            if len(terms) != arity[name]:
                raise PDDLError(
                    f"{source}: {where} atom {text}: {name} takes {arity[name]} argument(s), "
                    f"not {len(terms)}"
                )
            for term in terms:
                if isinstance(term, Constant) and str(term.name).lower() not in objects:
                    raise PDDLError(
                        f"{source}: {where} atom {text} names unknown object "
                        f"{one_of(str(term.name).lower(), objects)}"
                    )
