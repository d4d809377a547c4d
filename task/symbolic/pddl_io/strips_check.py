"""The STRIPS check: the first construct of PDDL text that the planners cannot plan with.

The planners plan STRIPS with equality; `check_strips` names the line and the feature of the
first construct beyond it (derived predicates, negative or disjunctive or quantified
preconditions, conditional, universal or non-deterministic effects, numeric fluents, goals
beyond a conjunction of atoms) in one `PDDLError` line.
"""

from __future__ import annotations

from task.errors import PDDLError
from task.symbolic.pddl_io.style import keywords
from task.symbolic.pddl_io.text import one_line
from task.symbolic.pddl_io.tree import Node, after, define, lists

_PRECONDITION = {
    "or": "disjunctive precondition (or)",
    "imply": "disjunctive precondition (imply)",
    "forall": "universal precondition (forall)",
    "exists": "existential precondition (exists)",
    **{op: f"numeric fluent ({op})" for op in (">", "<", ">=", "<=")},
}
_EFFECT = {
    "when": "conditional effect (when)",
    "forall": "universal effect (forall)",
    "oneof": "non-deterministic effect (oneof)",
    **{
        op: f"numeric fluent ({op})"
        for op in ("increase", "decrease", "assign", "scale-up", "scale-down")
    },
}
_GOAL = {**_PRECONDITION, "not": "negative goal (not)"}
_SUPPORTED = "STRIPS: and, atoms, not atoms in effects, = and not = in preconditions"


def _first_beyond(node: object, features: dict[str, str], negative: str | None):
    """The first list under ``node`` whose head is in ``features`` (or a ``not`` of anything
    but ``=``, named ``negative``): ``(list, feature)`` or None."""
    if not isinstance(node, Node):
        return None
    for inner in lists(node):
        if inner.head in features:
            return inner, features[inner.head]
        if negative and inner.head == "not":
            arg = inner.items[1] if len(inner.items) > 1 else None
            if not (isinstance(arg, Node) and arg.head == "="):
                return inner, negative
    return None


def check_strips(text: str, source: str) -> None:
    """PDDLError naming ``source``, the line and the feature of the first construct of domain
    or problem text that the planners cannot plan with (they plan STRIPS with equality):
    derived predicates, negative or disjunctive or quantified preconditions, conditional,
    universal or non-deterministic effects, numeric fluents in actions (action costs
    included), goals beyond a conjunction of atoms. Text that does not balance passes (the
    parser says where)."""
    root = define(keywords(text))
    found = None
    for node in root.items[2:] if root is not None else ():
        if not isinstance(node, Node) or found:
            continue
        if node.head == ":derived":
            found = node, "derived predicate (:derived)"
        elif node.head == ":action":
            pre, eff = after(node, ":precondition"), after(node, ":effect")
            found = _first_beyond(pre, _PRECONDITION, "negative precondition (not)")
            found = found or _first_beyond(eff, _EFFECT, None)
        elif node.head == ":goal":
            found = _first_beyond(after(node, ":goal"), _GOAL, None)
    if found:
        where, feature = found
        snippet = one_line(text[where.start : where.end])
        snippet = snippet if len(snippet) <= 60 else snippet[:57] + "..."
        raise PDDLError(
            f"{source}: line {where.line}: {feature} {snippet} is not supported "
            f"(supported: {_SUPPORTED})"
        )
