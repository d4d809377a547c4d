"""What one planner run holds once and passes down to its windows: the run's context (the
domain, the settings, the generator, the sources from outside, the deadlines) and its
progress (per problem, where its plan stands in the world).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import torch

from task.beliefs import BeliefSource
from task.config import PlannerConfig
from task.costs import CostSourceBase
from task.domains.base import Domain, State
from task.problem import Problem
from task.symbolic.lazy_search import LazyResult


@dataclass(frozen=True)
class PlanContext:
    """The shared inputs of every window of one run of `task.planner.plan_batch` over some
    problems (all of one domain): ``source`` gives each window soft beliefs (`task.beliefs`),
    ``costs`` move costs (`task.costs`); ``indices`` are the problems' positions in the
    caller's list (what the sources are told). ``windows_end``: the windows' deadline, and
    ``deadline`` the run's (`time.perf_counter` values, None: none); the windows end earlier
    when the fallback searches in the rest (`PlannerConfig.window_share`)."""

    domain: Domain
    config: PlannerConfig
    generator: torch.Generator  # CPU: the same draws on every device
    source: BeliefSource | None = None
    costs: CostSourceBase | None = None  # `task.costs.cost_source`: its members all there
    indices: Sequence[int] = ()
    fallback: bool = False  # the complete fallback search runs after the windows
    windows_end: float | None = None
    deadline: float | None = None

    @property
    def plain(self) -> bool:
        """Whether the windows plan without beliefs and move costs (on the true state alone)."""
        return self.source is None and self.costs is None


@dataclass(frozen=True)
class Progress:
    """Per problem of one run (each list indexed like its problems), where its plan stands:
    the loop updates the entries as the windows execute moves."""

    states: list[State]  # the world
    visited: list[set]  # every world state its plan passed through
    moves: list[list]  # the moves executed so far
    solved: list[bool]
    illegal: list[str | None]  # why its last move is illegal in the world (None: all legal)
    windows: list[int]  # windows planned
    misread: list[int]  # windows decoded against a state not the world's
    trigger: list[str | None]  # why the fallback takes over (None: it has not)
    safe: list[int]  # moves taken without a window (`PlannerConfig.safe_from`)
    cut: list[int]  # windows cut before a move priced out in its own state
    searched: dict[int, LazyResult]  # the fallback search of each problem it ran for
    improved: dict[int, dict]  # the anytime improvement's stats of each problem it ran for

    @classmethod
    def start(cls, domain: Domain, problems: Sequence[Problem]) -> Progress:
        """Every problem at its initial state, solved when that is already a goal."""
        states = [domain.initial_state(p) for p in problems]
        n = len(problems)
        return cls(
            states=states,
            visited=[{s} for s in states],
            moves=[[] for _ in problems],
            solved=[domain.is_goal(p, s) for p, s in zip(problems, states, strict=True)],
            illegal=[None] * n,
            windows=[0] * n,
            misread=[0] * n,
            trigger=[None] * n,
            safe=[0] * n,
            cut=[0] * n,
            searched={},
            improved={},
        )
