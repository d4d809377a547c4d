"""The one exception family for misuse: bad PDDL, unknown names, wrong shapes, missing files.

Outcomes the loop must react to (no plan found, invalid plan) are values, not exceptions; see
`task.problem.PlanStatus`. Messages are one line, name the bad input and list what is valid.
"""

from __future__ import annotations


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


class DataError(TampError):
    """Benchmark data (e.g. the PlanBench checkout) is missing or does not match its manifest."""
