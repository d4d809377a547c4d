"""The one exception family for misuse: bad PDDL, unknown names, wrong shapes, missing files.

Outcomes the loop must react to (no plan found, invalid plan) are values, not exceptions; see
`task.problem.PlanStatus`. Messages are one line, name the bad input and list what is valid.
"""

from __future__ import annotations

import enum
from typing import TypeVar

Mode = TypeVar("Mode", bound=enum.StrEnum)


class TampError(Exception):
    """Base class of every error soft-tamp raises on bad input."""


class PDDLError(TampError):
    """A PDDL file is missing, malformed, or uses something the domain cannot express."""


class ProblemError(TampError):
    """A problem, state, move or plan names something that does not exist or is inconsistent."""


def one_of(name: str, valid: object) -> str:
    """Format ``'x' (valid: a, b, c)`` for error messages; ``'x' (valid: none)`` when nothing
    is."""
    items = ", ".join(str(v) for v in valid) or "none"
    return f"{name!r} (valid: {items})"


def member(kind: type[Mode], value: object, what: str, error: type[TampError] = TampError) -> Mode:
    """``value`` (a member of the mode enum ``kind``, or its string) as that member: the one
    place a mode's name becomes its enum. An unknown ``value`` raises ``error`` (a `TampError`)
    ``unknown <what> 'x' (valid: a, b, c)``."""
    try:
        return kind(value)
    except ValueError:
        raise error(f"unknown {what} {one_of(value, [m.value for m in kind])}") from None


class DataError(TampError):
    """Benchmark data (e.g. the PlanBench checkout) is missing or does not match its manifest."""
