"""A parsed PDDL domain's signature: what recognises a domain whatever its file's layout."""

from __future__ import annotations

from pddl.core import Domain


def signature(domain: Domain) -> tuple[frozenset, frozenset]:
    """Action and predicate names with their arities, lowercased."""
    actions = frozenset((str(a.name).lower(), len(a.parameters)) for a in domain.actions)
    predicates = frozenset((str(p.name).lower(), p.arity) for p in domain.predicates)
    return actions, predicates
