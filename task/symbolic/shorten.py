"""Shorter plans by taking moves out: cycles cut and redundant moves eliminated, over the crisp
side of any domain (``check_move``, ``apply_move``, ``is_goal``, ``initial_state``).

Receding windows and the greedy fallback search (`task.symbolic.lazy_search.lazy_greedy`) can
return plans with detours: a state visited twice (a *cycle*: everything between the visits is
cut), or a move whose effect is undone or never used (picked up, put back). *Greedy action
elimination* (Fink & Yang 1992; Nakhost & Müller 2010) finds the latter: for each move in turn,
drop it together with every later move that no longer applies without it; keep the shorter
plan when it still reaches the goal. Both only remove moves, and every plan returned is
replayed from the initial state to the goal, so it stays valid whenever the input was.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import Protocol

from task.problem import Move, Problem


class ReplayDomain(Protocol):
    """The crisp side of a domain that shortening needs (`task.domains.base.Domain` has it)."""

    def initial_state(self, problem: Problem) -> Hashable: ...

    def check_move(self, problem: Problem, state: Hashable, move: Move) -> str | None: ...

    def apply_move(self, problem: Problem, state: Hashable, move: Move) -> Hashable: ...

    def is_goal(self, problem: Problem, state: Hashable) -> bool: ...


def _states(domain: ReplayDomain, problem: Problem, moves: Sequence[Move]) -> list[Hashable]:
    """The states a valid plan passes through, the initial one first. -> len(moves) + 1"""
    states = [domain.initial_state(problem)]
    for move in moves:
        states.append(domain.apply_move(problem, states[-1], move))
    return states


def cut_cycles(domain: ReplayDomain, problem: Problem, moves: Sequence[Move]) -> tuple:
    """``moves`` with every cycle cut: from each state, on from its last visit."""
    states = _states(domain, problem, moves)
    last = {s: k for k, s in enumerate(states)}
    out, k = [], 0
    while k < len(moves):
        k = last[states[k]]
        if k < len(moves):
            out.append(moves[k])
            k += 1
    return tuple(out)


def eliminate(domain: ReplayDomain, problem: Problem, moves: Sequence[Move]) -> tuple:
    """Greedy action elimination (module docstring) of a plan that reaches the goal: each move,
    first to last, is dropped when the goal is still reached without it and the later moves
    that then no longer apply."""
    plan = list(moves)
    states = _states(domain, problem, plan)
    k = 0
    while k < len(plan):
        state, kept = states[k], []
        for move in plan[k + 1 :]:
            if domain.check_move(problem, state, move) is None:
                state = domain.apply_move(problem, state, move)
                kept.append(move)
        if domain.is_goal(problem, state):
            plan[k:] = kept
            states[k + 1 :] = _states_from(domain, problem, states[k], kept)
        else:
            k += 1
    return tuple(plan)


def _states_from(domain, problem: Problem, state: Hashable, moves: Sequence[Move]) -> list:
    """The states after each of ``moves`` from ``state``. -> len(moves)"""
    out = []
    for move in moves:
        state = domain.apply_move(problem, state, move)
        out.append(state)
    return out


def shorten(domain: ReplayDomain, problem: Problem, moves: Sequence[Move]) -> tuple:
    """``moves`` (a plan that reaches the goal) with cycles cut, then redundant moves
    eliminated; never longer, and still a plan to the goal."""
    return eliminate(domain, problem, cut_cycles(domain, problem, moves))


def merge_runs(
    domain: ReplayDomain,
    problem: Problem,
    start: Hashable,
    moves: Sequence[Move],
    allowed: Callable[[Hashable, Move], bool] | None = None,
) -> tuple:
    """``moves`` from ``start`` with every run of moves of one entity made one move where that
    is the same: x onto a, then x onto b, becomes x onto b when that move applies where the
    first did, is ``allowed`` there (a cost source's feasibility, None: any legal move) and
    leads to the same state; a run that ends where it began is cut. Every state after a run
    is the one it was, so the later moves apply as before. A greedy search's plans park a
    block two or three times in a row; this takes that out without a replay of the rest.
    Relational moves (`task.problem.Move`) only: other actions (the lift's) stay."""
    plan = list(moves)
    state, k = start, 0
    while k < len(plan):
        after = domain.apply_move(problem, state, plan[k])
        if k + 1 < len(plan) and _same_entity(plan[k], plan[k + 1]):
            end = domain.apply_move(problem, after, plan[k + 1])
            if end == state:  # there and back
                del plan[k : k + 2]
                continue
            merged = Move(plan[k].entity, plan[k + 1].target)
            if (
                domain.check_move(problem, state, merged) is None
                and (allowed is None or allowed(state, merged))
                and domain.apply_move(problem, state, merged) == end
            ):
                plan[k : k + 2] = [merged]
                continue
        state, k = after, k + 1
    return tuple(plan)


def _same_entity(first, then) -> bool:
    """Whether two actions are relational moves (`Move`) of one entity."""
    return isinstance(first, Move) and isinstance(then, Move) and first.entity == then.entity
