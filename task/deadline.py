"""One wall-clock deadline for a whole command: every phase (grounding, the unsolvability
proofs, planning, the exhaustive proof, the improvement) is handed the same `Deadline` and
checks it, so a time limit bounds the command's work, not one phase of it.

Plain standard library: the crisp side (`task.symbolic`) uses it without torch.
"""

from __future__ import annotations

import time
from dataclasses import dataclass


class TimeLimitReached(Exception):
    """A phase found its `Deadline` passed and stopped (what it did so far proves nothing)."""


@dataclass(frozen=True)
class Deadline:
    """``at``: the ``time.perf_counter()`` value after which work stops (None: no limit);
    ``limit_s``: the limit it was made from, for messages."""

    at: float | None = None
    limit_s: float | None = None

    @classmethod
    def after(cls, seconds: float | None, start: float | None = None) -> Deadline:
        """``seconds`` from ``start`` (default: now); no limit when ``seconds`` is None."""
        if seconds is None:
            return cls()
        return cls((time.perf_counter() if start is None else start) + seconds, seconds)

    def passed(self) -> bool:
        """Whether the deadline has passed (never, without a limit)."""
        return self.at is not None and time.perf_counter() >= self.at

    def left_s(self) -> float | None:
        """Seconds left, at least 0 (None without a limit)."""
        return None if self.at is None else max(0.0, self.at - time.perf_counter())

    def within(self, seconds: float | None) -> float | None:
        """The ``time.perf_counter()`` value a phase allowed ``seconds`` of its own stops at:
        ``seconds`` from now, or the deadline when that comes first (None: neither)."""
        own = None if seconds is None else time.perf_counter() + seconds
        ends = [t for t in (own, self.at) if t is not None]
        return min(ends) if ends else None

    def check(self, phase: str) -> None:
        """Raise `TimeLimitReached` naming ``phase`` when the deadline has passed."""
        if self.passed():
            raise TimeLimitReached(f"time limit ({self.limit_s:g} s) reached while {phase}")


NO_DEADLINE = Deadline()  # no limit: the default of every phase that takes a deadline
