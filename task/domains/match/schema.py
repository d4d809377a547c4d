"""A parsed PDDL domain as plain data the matcher compares: types, predicates, action schemas.

`shape` reads a `pddl` domain into a `Shape`: every name lowercased, each action's
precondition, add and delete lists as sets of atoms whose terms are parameter positions
(``int``) or constant names (``str``). Only what the hand-written domains use can match:
conjunctions of positive atoms and their negations in effects, typed or untyped parameters
(one type each). Anything else (``either`` types, equality, negative or disjunctive
preconditions, conditional effects, ...) makes `shape` return a one-line reason instead.
"""

from __future__ import annotations

from dataclasses import dataclass

from pddl.core import Domain
from pddl.logic.base import And, Not
from pddl.logic.predicates import Predicate
from pddl.logic.terms import Variable

OBJECT = "object"  # the type of an untyped parameter or object
Term = int | str  # a parameter position, or a constant's name
Pattern = tuple  # (predicate, Term, ...)


@dataclass(frozen=True)
class Schema:
    """One action: parameter names (no ``?``) and types, and its atom patterns."""

    name: str
    params: tuple[str, ...]
    types: tuple[str, ...]
    pre: frozenset[Pattern]
    add: frozenset[Pattern]
    delete: frozenset[Pattern]

    @property
    def lists(self) -> tuple[frozenset[Pattern], frozenset[Pattern], frozenset[Pattern]]:
        """``(pre, add, delete)``, the order of `LISTS`."""
        return (self.pre, self.add, self.delete)


LISTS = ("precondition", "add list", "delete list")  # how messages name Schema.lists


@dataclass(frozen=True)
class Shape:
    """A domain's structure. ``parents``: type -> parent type (None for a root);
    ``predicates``: name -> argument types; ``constants``: name -> type."""

    name: str
    parents: tuple[tuple[str, str | None], ...]
    predicates: tuple[tuple[str, tuple[str, ...]], ...]
    constants: tuple[tuple[str, str], ...]
    actions: tuple[Schema, ...]

    def parent(self, kind: str) -> str | None:
        """The parent of type ``kind`` (None for ``object`` and roots)."""
        found = dict(self.parents).get(kind)
        return None if found == OBJECT else found

    def used(self) -> frozenset[str]:
        """The predicates some action mentions."""
        return frozenset(a[0] for s in self.actions for atoms in s.lists for a in atoms)


def _type(tags: frozenset) -> str | None:
    """The one type of a term (``object`` when untyped), None for ``either``."""
    names = sorted(str(t).lower() for t in tags)
    if len(names) > 1:
        return None
    return names[0] if names else OBJECT


def _pattern(pred: Predicate, params: dict[str, int]) -> Pattern | None:
    terms: list[Term] = []
    for term in pred.terms:
        name = str(term.name).lower()
        if isinstance(term, Variable):
            if name not in params:
                return None
            terms.append(params[name])
        else:
            terms.append(name)
    return (str(pred.name).lower(), *terms)


def _literals(formula: object, params: dict[str, int], out: list, negated: list) -> bool:
    """Flatten a conjunction of atoms and negated atoms into ``out`` and ``negated``; False
    for anything else."""
    if formula is None:
        return True
    if isinstance(formula, And):
        return all(_literals(op, params, out, negated) for op in formula.operands)
    if isinstance(formula, Predicate):
        out.append(_pattern(formula, params))
        return out[-1] is not None
    if isinstance(formula, Not) and isinstance(formula.argument, Predicate):
        negated.append(_pattern(formula.argument, params))
        return negated[-1] is not None
    return False


def _schema(action) -> Schema | str:
    name = str(action.name).lower()
    params = tuple(str(p.name).lower() for p in action.parameters)
    types = tuple(_type(p.type_tags) for p in action.parameters)
    if None in types:
        return f"action {name!r} has a parameter of several types (either)"
    index = {p: i for i, p in enumerate(params)}
    pre, negative, add, delete = [], [], [], []
    if not _literals(action.precondition, index, pre, negative) or negative:
        return f"action {name!r}: its precondition is not a conjunction of atoms"
    if not _literals(action.effect, index, add, delete):
        return f"action {name!r}: its effect is not a conjunction of atoms and negated atoms"
    return Schema(name, params, types, frozenset(pre), frozenset(add), frozenset(delete))


def shape(domain: Domain) -> Shape | str:
    """The `Shape` of a parsed domain, or a one-line reason it cannot match any."""
    if domain.derived_predicates or getattr(domain, "functions", None):
        return f"domain {str(domain.name)!r} has derived predicates or functions"
    actions = []
    for action in sorted(domain.actions, key=lambda a: str(a.name).lower()):
        found = _schema(action)
        if isinstance(found, str):
            return found
        actions.append(found)
    parents = tuple(
        sorted(
            (str(t).lower(), None if p is None else str(p).lower()) for t, p in domain.types.items()
        )
    )
    predicates = []
    for pred in domain.predicates:
        types = tuple(_type(t.type_tags) for t in pred.terms)
        if None in types:
            return f"predicate {str(pred.name).lower()!r} has an argument of several types"
        predicates.append((str(pred.name).lower(), types))
    constants = []
    for const in domain.constants:
        kind = _type(const.type_tags)
        if kind is None:
            return f"constant {str(const.name).lower()!r} has several types"
        constants.append((str(const.name).lower(), kind))
    return Shape(
        str(domain.name).lower(),
        parents,
        tuple(sorted(predicates)),
        tuple(sorted(constants)),
        tuple(actions),
    )
