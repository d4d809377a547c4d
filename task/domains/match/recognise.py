"""Which hand-written domain a parsed PDDL domain is, up to renaming: `match_domain`.

Every registered domain but the generic lift is a candidate (its own PDDL file,
``pddl_domain_text``). A candidate matches when `search.find` pairs all its actions,
predicates, types and constants with the user's with no defect (`Match`, with the `Renaming`);
when one precondition, add or delete atom is all that differs it is a `NearMiss`, whose
``reason`` is the one line saying why the lift plans it instead. Results are cached by the
domain's structure, so a benchmark of many problems of one domain matches it once.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

from pddl.core import Domain

from task.domains import GENERIC, get_domain, names
from task.domains.match.renaming import Renaming
from task.domains.match.schema import Shape, shape
from task.domains.match.search import explain, find


@dataclass(frozen=True)
class Match:
    """The user's domain is registered domain ``rules`` under ``renaming`` (possibly the
    identity: the hand-written file itself)."""

    rules: str
    renaming: Renaming


@dataclass(frozen=True)
class NearMiss:
    """The user's domain is registered domain ``rules`` but for one atom; ``reason`` says which,
    e.g. ``domain matches blocksworld-4ops except action 'grab': its delete list lacks
    (handempty)``."""

    rules: str
    reason: str


@functools.cache
def reference_domain(rules: str) -> Domain:
    """The parsed PDDL file of registered domain ``rules``."""
    from task.symbolic import pddl_io

    text = get_domain(rules).pddl_domain_text()
    return pddl_io.parse_domain(text, f"the {rules} domain")


@functools.cache
def _reference_shape(rules: str) -> Shape:
    found = shape(reference_domain(rules))
    assert not isinstance(found, str), found  # the hand-written files are plain STRIPS
    return found


def candidates() -> tuple[str, ...]:
    """The registered domains a PDDL domain can match (all but the generic lift)."""
    return tuple(n for n in names() if n != GENERIC)


@functools.lru_cache(maxsize=64)
def _match(user: Shape, among: tuple[str, ...]) -> Match | NearMiss | None:
    for rules in among:
        found = find(user, _reference_shape(rules))
        if found is not None:
            return Match(rules, found[0])
    for rules in among:
        found = find(user, _reference_shape(rules), budget=1)
        if found is not None:
            renaming, defects = found
            line = explain(defects[0], renaming)
            return NearMiss(rules, f"domain matches {renaming.reference} except {line}")
    return None


def match_domain(domain: Domain, among: Sequence[str] | None = None) -> Match | NearMiss | None:
    """The registered domain (of ``among``, default `candidates`) that ``domain`` is up to
    renaming: a `Match`, a `NearMiss` (one atom off), or None (nothing close)."""
    user = shape(domain)
    if isinstance(user, str):
        return None
    return _match(user, tuple(candidates() if among is None else among))


def recognise(pddl_domain: Domain) -> str:
    """The name of the hand-written domain a parsed PDDL domain is up to renaming (by its
    structure, `match_domain`), else the generic lift (`task.domains.GENERIC`)."""
    found = match_domain(pddl_domain)
    return found.rules if isinstance(found, Match) else GENERIC
