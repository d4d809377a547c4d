"""Grounded STRIPS semantics over a parsed `pddl` domain (pyperplan style).

A state is a frozenset of ground atoms, each a lowercase tuple such as ``("on", "a", "b")``.
Preconditions are conjunctions of positive and negative literals; effects are conjunctions of
add (positive) and delete (``not``) literals; ``apply`` deletes first, then adds. Untyped and
typed domains both work (arguments are checked against parameter types). Names are lowercased
throughout, since PDDL is case-insensitive and plan files are written in lowercase.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from typing import NamedTuple

from pddl.action import Action as PDDLAction
from pddl.core import Domain
from pddl.core import Problem as PDDLProblem
from pddl.logic.base import And, Not
from pddl.logic.predicates import Predicate
from pddl.logic.terms import Variable

from task.errors import PDDLError, ProblemError, one_of
from task.problem import Action

Atom = tuple[str, ...]
State = frozenset[Atom]


class GroundAction(NamedTuple):
    """The ground preconditions and effects of one action; unpacks as a 4-tuple."""

    pre_pos: frozenset[Atom]
    pre_neg: frozenset[Atom]
    add: frozenset[Atom]
    delete: frozenset[Atom]


def atom_str(atom: Atom) -> str:
    """``("on", "a", "b")`` -> ``"(on a b)"``."""
    return "(" + " ".join(atom) + ")"


def atom_of(pred: Predicate, binding: dict[str, str] | None = None) -> Atom:
    """``pred`` as an `Atom` (predicate and constants lower-case), its variables replaced by
    ``binding`` (variable name -> object); PDDLError for a variable ``binding`` does not bind."""
    args = []
    for term in pred.terms:
        key = str(term.name).lower()
        if isinstance(term, Variable):
            if binding is None or key not in binding:
                raise PDDLError(f"unbound variable ?{key} in {pred}")
            args.append(binding[key])
        else:
            args.append(key)
    return (str(pred.name).lower(), *args)


def flat_literals(formula: object, what: str) -> list[tuple[bool, Predicate]]:
    """Flatten a conjunction of literals into ``(positive, predicate)`` pairs."""
    if formula is None:
        return []
    if isinstance(formula, Predicate):
        return [(True, formula)]
    if isinstance(formula, Not) and isinstance(formula.argument, Predicate):
        return [(False, formula.argument)]
    if isinstance(formula, And):
        return [lit for op in formula.operands for lit in flat_literals(op, what)]
    raise PDDLError(f"{what}: {formula} is not STRIPS (supported: and, not, atoms)")


def initial_state(problem: PDDLProblem) -> State:
    """The initial state: the problem's ``:init`` atoms."""
    atoms = []
    for fact in problem.init:
        if not isinstance(fact, Predicate):
            raise PDDLError(f"problem {problem.name}: init fact {fact} is not a STRIPS atom")
        atoms.append(atom_of(fact))
    return frozenset(atoms)


def goal_atoms(problem: PDDLProblem) -> tuple[Atom, ...]:
    """The goal as positive atoms in file order; PDDLError for anything but a conjunction."""
    literals = flat_literals(problem.goal, f"problem {problem.name}: goal")
    negative = [p for positive, p in literals if not positive]
    if negative:
        raise PDDLError(
            f"problem {problem.name}: goal literal (not {negative[0]}) is not supported "
            "(goals are conjunctions of positive atoms)"
        )
    return tuple(dict.fromkeys(atom_of(p) for _, p in literals))


def objects(domain: Domain, problem: PDDLProblem) -> tuple[str, ...]:
    """The problem's objects and the domain's constants, lowercased and sorted."""
    names = {str(o.name).lower() for o in (*problem.objects, *domain.constants)}
    return tuple(sorted(names))


def _schemas(domain: Domain) -> dict[str, PDDLAction]:
    return {str(a.name).lower(): a for a in domain.actions}


def is_subtype(tag: str, wanted: str, parents: dict[str, str | None]) -> bool:
    """Whether type ``tag`` is ``wanted`` or below it in the type tree ``parents`` (type ->
    its parent, None at a root); every type is an ``object``."""
    seen = set()
    while tag is not None and tag not in seen:
        if tag == wanted:
            return True
        seen.add(tag)
        tag = parents.get(tag)
    return wanted == "object"


def object_types(domain: Domain, problem: PDDLProblem) -> dict[str, frozenset[str]]:
    """Each object and constant (lower-case name) -> its declared types (``object`` when
    untyped)."""
    objs = (*problem.objects, *domain.constants)
    return {
        str(o.name).lower(): frozenset(str(t).lower() for t in o.type_tags) or frozenset({"object"})
        for o in objs
    }


def ground(domain: Domain, problem: PDDLProblem, action: Action) -> GroundAction:
    """Ground ``action`` against ``domain`` with ``problem``'s objects.

    Raises ProblemError for an unknown action name, a wrong number of arguments, an unknown
    object or an argument of the wrong type, and PDDLError for a schema that is not STRIPS.
    """
    schemas = _schemas(domain)
    name = action.name.lower()
    if name not in schemas:
        raise ProblemError(f"{action}: unknown action {one_of(action.name, sorted(schemas))}")
    schema = schemas[name]
    params = [str(p.name).lower() for p in schema.parameters]
    if len(params) != len(action.args):
        raise ProblemError(
            f"{action}: {name} takes {len(params)} arguments "
            f"({' '.join('?' + p for p in params)}), got {len(action.args)}"
        )
    types = object_types(domain, problem)
    parents = {str(k).lower(): (v and str(v).lower()) for k, v in domain.types.items()}
    args = tuple(a.lower() for a in action.args)
    for param, arg in zip(schema.parameters, args, strict=True):
        if arg not in types:
            raise ProblemError(f"{action}: unknown object {one_of(arg, sorted(types))}")
        wanted = {str(t).lower() for t in param.type_tags}
        if wanted and not any(is_subtype(t, w, parents) for t in types[arg] for w in wanted):
            raise ProblemError(
                f"{action}: {arg} is not of type {' or '.join(sorted(wanted))} for ?{param.name}"
            )
    binding = dict(zip(params, args, strict=True))
    pre = flat_literals(schema.precondition, f"action {name}: precondition")
    eff = flat_literals(schema.effect, f"action {name}: effect")
    return GroundAction(
        frozenset(atom_of(p, binding) for pos, p in pre if pos),
        frozenset(atom_of(p, binding) for pos, p in pre if not pos),
        frozenset(atom_of(p, binding) for pos, p in eff if pos),
        frozenset(atom_of(p, binding) for pos, p in eff if not pos),
    )


def ground_all(domain: Domain, problem: PDDLProblem) -> tuple[tuple[Action, GroundAction], ...]:
    """Every well-typed ground action of the problem (exponential in arity; small problems)."""
    types = object_types(domain, problem)
    parents = {str(k).lower(): (v and str(v).lower()) for k, v in domain.types.items()}
    out = []
    for name, schema in sorted(_schemas(domain).items()):
        domains = []
        for param in schema.parameters:
            wanted = {str(t).lower() for t in param.type_tags}
            domains.append(
                [
                    o
                    for o in sorted(types)
                    if not wanted
                    or any(is_subtype(t, w, parents) for t in types[o] for w in wanted)
                ]
            )
        for args in itertools.product(*domains):
            action = Action(name, args)
            out.append((action, ground(domain, problem, action)))
    return tuple(out)


def unmet(state: State, action: GroundAction) -> tuple[str, ...]:
    """The preconditions of ``action`` that fail in ``state``, as sorted strings."""
    missing = [atom_str(a) for a in action.pre_pos - state]
    present = [f"(not {atom_str(a)})" for a in action.pre_neg & state]
    return tuple(sorted(missing) + sorted(present))


def applicable(state: State, action: GroundAction) -> bool:
    """Whether every positive precondition holds and no negative one does."""
    return action.pre_pos <= state and not (action.pre_neg & state)


def apply(state: State, action: GroundAction) -> State:
    """The successor state: delete effects first, then add effects (no applicability check)."""
    return (state - action.delete) | action.add


def holds(state: State, atoms: Iterable[Atom]) -> bool:
    """Whether every atom holds in ``state``."""
    return all(a in state for a in atoms)
