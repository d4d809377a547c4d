"""Fast grounding by relaxed reachability: the ground actions the delete relaxation reaches.

`strips.ground_all` enumerates every well-typed argument tuple of every action; `reachable`
instead grounds the way Fast Downward's and pyperplan's grounders do. Predicates that no action
adds or deletes are *static*; their facts come from ``:init`` alone. Each action's positive
preconditions are joined one at a time (static ones first, then those sharing the most
variables already bound), binding variables incrementally against indexed facts and checking
parameter types (``either`` and type hierarchies, as `strips` does) as each variable is bound.
A fixpoint over rounds then grounds every action whose preconditions all hold among the atoms
reached so far and adds its add effects (deletes are ignored) until nothing new appears.

Supported: STRIPS with typed or untyped objects and constants, conjunctions of positive atoms,
``(= ?x ?y)`` and ``(not (= ?x ?y))`` in preconditions (checked while binding, so they do not
appear in the ground action), add and delete effects. Anything else (negative or disjunctive
preconditions, ``forall``/``exists``, conditional effects, numeric fluents, derived predicates)
raises `PDDLError` naming the feature and the action. Parameters that occur in no precondition
range over every object of their type. The ground actions are those of `strips.ground` for the
same arguments, minus the equality literals that `strips` rejects.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from typing import NamedTuple

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem
from pddl.logic.base import And, ExistsCondition, ForallCondition, Imply, Not, OneOf, Or
from pddl.logic.effects import Forall, When
from pddl.logic.functions import FunctionExpression
from pddl.logic.predicates import EqualTo, Predicate
from pddl.logic.terms import Variable

from task.deadline import NO_DEADLINE, Deadline
from task.errors import PDDLError
from task.problem import Action
from task.symbolic.strips import Atom, GroundAction, initial_state, is_subtype, object_types

CHECK_EVERY = 1024  # bindings between two looks at the deadline (a look costs ~0.1 us)

_FEATURES = (
    (Not, "negative precondition"),
    (Or, "disjunctive precondition"),
    (Imply, "disjunctive precondition (imply)"),
    (OneOf, "non-deterministic effect (oneof)"),
    (ForallCondition, "universal precondition (forall)"),
    (ExistsCondition, "existential precondition (exists)"),
    (When, "conditional effect (when)"),
    (Forall, "universal effect (forall)"),
    (FunctionExpression, "numeric fluent"),
)


class Grounding(NamedTuple):
    """Reachable ground actions, sorted by (name, args), and the sorted reachable atoms."""

    actions: tuple[tuple[Action, GroundAction], ...]
    atoms: tuple[Atom, ...]


class _Schema(NamedTuple):
    """An action with atoms as ``(pred, term, ...)``; a variable term is ``"?name"``."""

    name: str
    params: tuple[str, ...]
    pre: tuple[Atom, ...]  # join order: static first, then most bound variables
    equal: tuple[tuple[bool, str, str], ...]  # (positive, left, right)
    add: tuple[Atom, ...]
    delete: tuple[Atom, ...]


def _term(term: object) -> str:
    name = str(term.name).lower()
    return "?" + name if isinstance(term, Variable) else name


def _pattern(pred: Predicate) -> Atom:
    return (str(pred.name).lower(), *(_term(t) for t in pred.terms))


def _unsupported(formula: object, where: str, supported: str) -> PDDLError:
    feature = next((f for cls, f in _FEATURES if isinstance(formula, cls)), "formula")
    return PDDLError(f"{where}: {feature} {formula} is not supported (supported: {supported})")


def _conditions(formula: object, where: str, pre: list, equal: list) -> None:
    """Split a precondition into atom patterns and ``(positive, left, right)`` equalities."""
    if formula is None:
        return
    if isinstance(formula, And):
        for op in formula.operands:
            _conditions(op, where, pre, equal)
    elif isinstance(formula, Predicate):
        pre.append(_pattern(formula))
    elif isinstance(formula, EqualTo):
        equal.append((True, _term(formula.left), _term(formula.right)))
    elif isinstance(formula, Not) and isinstance(formula.argument, EqualTo):
        equal.append((False, _term(formula.argument.left), _term(formula.argument.right)))
    else:
        raise _unsupported(formula, where, "and, atoms, =, not =")


def _effects(formula: object, where: str, add: list, delete: list) -> None:
    if formula is None:
        return
    if isinstance(formula, And):
        for op in formula.operands:
            _effects(op, where, add, delete)
    elif isinstance(formula, Predicate):
        add.append(_pattern(formula))
    elif isinstance(formula, Not) and isinstance(formula.argument, Predicate):
        delete.append(_pattern(formula.argument))
    else:
        raise _unsupported(formula, where, "and, atoms, not atoms")


def _join_order(pre: list[Atom], static: set[str]) -> tuple[Atom, ...]:
    """Greedy order: static atoms first, then the atom with the most variables already bound."""
    order, bound, rest = [], set(), list(dict.fromkeys(pre))
    while rest:
        best = max(
            rest,
            key=lambda a: (a[0] in static, sum(t in bound for t in a[1:] if t[0] == "?")),
        )
        rest.remove(best)
        order.append(best)
        bound.update(t for t in best[1:] if t[0] == "?")
    return tuple(order)


def _schemas(domain: Domain) -> list[_Schema]:
    """The domain's actions, sorted by name, preconditions in join order."""
    if domain.derived_predicates:
        first = sorted(str(d.predicate) for d in domain.derived_predicates)[0]
        raise PDDLError(f"domain {domain.name}: derived predicate {first} is not supported")
    raw = []
    for action in sorted(domain.actions, key=lambda a: str(a.name).lower()):
        name = str(action.name).lower()
        params = tuple("?" + str(p.name).lower() for p in action.parameters)
        pre, equal, add, delete = [], [], [], []
        _conditions(action.precondition, f"action {name}: precondition", pre, equal)
        _effects(action.effect, f"action {name}: effect", add, delete)
        terms = {t for a in (*pre, *add, *delete) for t in a[1:]} | {
            t for _, *lr in equal for t in lr
        }
        unbound = sorted(t for t in terms if t[0] == "?" and t not in params)
        if unbound:
            raise PDDLError(f"action {name}: unbound variable {unbound[0]}")
        raw.append((name, params, pre, tuple(equal), tuple(add), tuple(delete)))
    fluent = {a[0] for *_, add, delete in raw for a in (*add, *delete)}
    static = {p for _, _, pre, *_ in raw for p, *_ in pre} - fluent
    return [_Schema(n, ps, _join_order(pre, static), *rest) for n, ps, pre, *rest in raw]


class _Facts:
    """Atoms by predicate, plus lazily built views keyed by the values at bound positions."""

    def __init__(self) -> None:
        self.atoms: set[Atom] = set()
        self.views: dict[tuple[str, tuple[int, ...]], dict[tuple[str, ...], list[Atom]]] = {}

    def add(self, atom: Atom) -> None:
        if atom not in self.atoms:
            self.atoms.add(atom)
            for (pred, positions), view in self.views.items():
                self._index(atom, pred, positions, view)

    @staticmethod
    def _index(atom: Atom, pred: str, positions: tuple[int, ...], view: dict) -> None:
        if atom[0] == pred and len(atom) > max(positions, default=0):
            view.setdefault(tuple(atom[i] for i in positions), []).append(atom)

    def lookup(self, pred: str, positions: tuple[int, ...], key: tuple[str, ...]) -> list[Atom]:
        if (pred, positions) not in self.views:
            self.views[pred, positions] = {}
            for atom in self.atoms:
                self._index(atom, pred, positions, self.views[pred, positions])
        return self.views[pred, positions].get(key, [])


def _equal_ok(equal: tuple[tuple[bool, str, str], ...], binding: dict[str, str]) -> bool:
    for positive, left, right in equal:
        x, y = binding.get(left, left), binding.get(right, right)
        if x[0] != "?" and y[0] != "?" and (x == y) != positive:
            return False
    return True


def _bindings(
    schema: _Schema, facts: _Facts, allowed: dict[str, frozenset[str]]
) -> Iterator[dict[str, str]]:
    """Every binding of the parameters under which all preconditions are among ``facts``."""

    def extend(i: int, binding: dict[str, str]) -> Iterator[dict[str, str]]:
        if i == len(schema.pre):
            yield binding
            return
        lit = schema.pre[i]
        terms = [binding.get(t, t) for t in lit[1:]]
        positions = tuple(j + 1 for j, t in enumerate(terms) if t[0] != "?")
        key = tuple(t for t in terms if t[0] != "?")
        for atom in facts.lookup(lit[0], positions, key):
            if len(atom) != len(lit):
                continue
            new = dict(binding)
            for var, value in zip(terms, atom[1:], strict=True):
                if var[0] != "?":
                    continue  # a constant or a bound variable: matched by the view's key
                if new.setdefault(var, value) != value or value not in allowed[var]:
                    break
            else:
                if _equal_ok(schema.equal, new):
                    yield from extend(i + 1, new)

    free = [p for p in schema.params if all(p not in a[1:] for a in schema.pre)]
    for binding in extend(0, {}):
        for values in itertools.product(*(sorted(allowed[p]) for p in free)):
            full = {**binding, **dict(zip(free, values, strict=True))}
            if not free or _equal_ok(schema.equal, full):
                yield full


def _substitute(atoms: tuple[Atom, ...], binding: dict[str, str]) -> frozenset[Atom]:
    return frozenset((a[0], *(binding.get(t, t) for t in a[1:])) for a in atoms)


def reachable(domain: Domain, problem: PDDLProblem, deadline: Deadline = NO_DEADLINE) -> Grounding:
    """Ground ``problem`` by relaxed reachability (see the module docstring).

    Raises PDDLError for a domain or problem that is not STRIPS in the supported fragment, and
    `TimeLimitReached` when ``deadline`` passes first (checked every `CHECK_EVERY` bindings).
    """
    schemas = _schemas(domain)
    types = object_types(domain, problem)
    parents = {str(k).lower(): (v and str(v).lower()) for k, v in domain.types.items()}
    facts = _Facts()
    for atom in sorted(initial_state(problem)):
        facts.add(atom)
    allowed: dict[str, dict[str, frozenset[str]]] = {}
    for action in domain.actions:
        name = str(action.name).lower()
        allowed[name] = {}
        for param in action.parameters:
            wanted = {str(t).lower() for t in param.type_tags}
            allowed[name]["?" + str(param.name).lower()] = frozenset(
                o
                for o in types
                if not wanted or any(is_subtype(t, w, parents) for t in types[o] for w in wanted)
            )
    found: dict[tuple[str, tuple[str, ...]], GroundAction] = {}
    bound = 0
    while True:
        new_atoms = []
        for schema in schemas:
            for binding in _bindings(schema, facts, allowed[schema.name]):
                if bound % CHECK_EVERY == 0:
                    deadline.check("grounding")
                bound += 1
                args = tuple(binding[p] for p in schema.params)
                if (schema.name, args) in found:
                    continue
                ground = GroundAction(
                    _substitute(schema.pre, binding),
                    frozenset(),
                    _substitute(schema.add, binding),
                    _substitute(schema.delete, binding),
                )
                found[schema.name, args] = ground
                new_atoms.extend(a for a in sorted(ground.add) if a not in facts.atoms)
        if not new_atoms:
            break
        for atom in new_atoms:
            facts.add(atom)
    actions = tuple((Action(n, args), found[n, args]) for n, args in sorted(found))
    return Grounding(actions, tuple(sorted(facts.atoms)))
