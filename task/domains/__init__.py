"""Registry of planning domains: one file each, picked up by name.

Adding a domain is one file in this folder exposing a ``DOMAIN`` object that satisfies
``task.domains.base.Domain``, plus one line in ``_DOMAINS`` below. ``base`` holds the protocol
and the soft batch every domain fills. A domain too large for one file keeps helpers beside it
under its own prefix: ``blocksworld_pddl`` (problem PDDL in and out) and ``blocksworld_states``
(full goal scenes, the most likely state of a perceived soft state).
"""

from __future__ import annotations

from task.domains import blocksworld
from task.domains.base import Domain
from task.errors import ProblemError, one_of

_DOMAINS: dict[str, Domain] = {blocksworld.NAME: blocksworld.DOMAIN}


def names() -> tuple[str, ...]:
    return tuple(_DOMAINS)


def get_domain(name: str) -> Domain:
    """The registered domain called ``name``; raises ProblemError listing the valid names."""
    try:
        return _DOMAINS[name]
    except KeyError:
        raise ProblemError(f"unknown domain {one_of(name, _DOMAINS)}") from None
