"""Registry of planning domains: one file each, picked up by name.

Adding a domain is one file in this folder exposing a ``DOMAIN`` object that satisfies
`task.domains.base.Domain`, plus its name in ``_NAMES`` below; modules are imported on first
use. ``base`` holds the protocol and the soft batch every domain fills. A domain too large for
one file keeps helpers beside it under its own prefix: ``blocksworld_pddl``, ``logistics_pddl``,
``sokoban_pddl`` (problem PDDL in and out), ``logistics_map`` (the static map and routes),
``sokoban_grid`` (the grid's static tables), ``strips_soft`` (the lift's tensors). ``strips``
is the generic soft lift of any grounded STRIPS domain: the planner of a PDDL domain no file is
written for, and the oracle the hand-written domains are tested on. The room ``match`` finds
the hand-written domain a PDDL domain is up to renaming (by structure, never by name;
`task.domains.match.recognise`) and keeps the user's names in plans; it builds on this
registry, which never imports it. The domains build on the crisp side (`task.symbolic`), which
never imports them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from task.errors import ProblemError, one_of

if TYPE_CHECKING:  # the registry itself stays light: no torch until a domain is used
    from task.domains.base import Domain

_NAMES = ("blocksworld", "logistics", "sokoban", "strips")
GENERIC = "strips"  # the generic lift: recognised last, matches any supported STRIPS domain


def names() -> tuple[str, ...]:
    return _NAMES


def get_domain(name: str) -> Domain:
    """The registered domain called ``name``; raises ProblemError listing the valid names."""
    if name not in _NAMES:
        raise ProblemError(f"unknown domain {one_of(name, _NAMES)}")
    return importlib.import_module(f"task.domains.{name}").DOMAIN
