"""The renaming between a hand-written domain's PDDL names and a user's: actions, predicates
(each with its argument order), types and constants. Object names are never renamed.

A `Renaming` translates both ways: ``to_user`` turns the hand-written domain's ground actions and
atoms into the user's (what plans, validation and messages speak), ``to_reference`` turns the
user's atoms into the hand-written domain's (how a user's problem is read). `speak` rewrites the
reference atoms inside a message. `user_actions` and `user_atoms` wrap a domain's ``to_actions``
and ``to_atoms`` so that a problem carrying a renaming (``Problem.renaming``) gets the user's
names back while the domain's own mapping stays written in its own names.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from task.problem import Action, Problem

Atom = tuple[str, ...]


@dataclass(frozen=True)
class Renamed:
    """One action's or predicate's two names; user argument ``j`` is reference argument
    ``order[j]`` (``order`` is a permutation of ``range(arity)``)."""

    reference: str
    user: str
    order: tuple[int, ...]

    def to_user(self, args: Sequence[str]) -> tuple[str, ...]:
        return tuple(args[i] for i in self.order)

    def to_reference(self, args: Sequence[str]) -> tuple[str, ...]:
        out = [""] * len(self.order)
        for j, i in enumerate(self.order):
            out[i] = args[j]
        return tuple(out)


@dataclass(frozen=True)
class Renaming:
    """How the user's domain ``domain`` names the hand-written domain ``reference`` (both PDDL
    domain names, lowercased). ``types`` and ``constants``: ``(reference, user)`` pairs."""

    reference: str
    domain: str
    actions: tuple[Renamed, ...]
    predicates: tuple[Renamed, ...]
    types: tuple[tuple[str, str], ...] = ()
    constants: tuple[tuple[str, str], ...] = ()

    @functools.cached_property
    def _by(self) -> dict[str, dict[str, Renamed]]:
        return {
            "action": {r.reference: r for r in self.actions},
            "action_back": {r.user: r for r in self.actions},
            "pred": {r.reference: r for r in self.predicates},
            "pred_back": {r.user: r for r in self.predicates},
        }

    @property
    def identity(self) -> bool:
        """Whether every name and argument order is the reference's own."""
        same = all(
            r.reference == r.user and r.order == tuple(range(len(r.order)))
            for r in (*self.actions, *self.predicates)
        )
        return same and all(a == b for a, b in (*self.types, *self.constants))

    def action(self, action: Action) -> Action:
        """A reference ground action in the user's names (unknown names pass unchanged)."""
        found = self._by["action"].get(action.name.lower())
        if found is None:
            return action
        return Action(found.user, found.to_user(self._constants(action.args)))

    def atom(self, atom: Atom) -> Atom:
        """A reference atom ``(pred, arg, ...)`` in the user's names."""
        found = self._by["pred"].get(atom[0])
        if found is None:
            return atom
        return (found.user, *found.to_user(self._constants(atom[1:])))

    def to_reference(self, atom: Atom) -> Atom | None:
        """A user atom in the reference's names; None for a predicate no action uses."""
        found = self._by["pred_back"].get(atom[0])
        if found is None:
            return None
        back = dict((u, r) for r, u in self.constants)
        return (found.reference, *(back.get(a, a) for a in found.to_reference(atom[1:])))

    def user_type(self, reference_type: str) -> str:
        return dict(self.types).get(reference_type, reference_type)

    def reference_type(self, user_type: str) -> str | None:
        """The reference type the user's type stands for (None: no action takes it)."""
        return {u: r for r, u in self.types}.get(user_type)

    def speak(self, text: str) -> str:
        """``text`` with every parenthesised reference atom or action in the user's names."""

        def one(found: re.Match) -> str:
            words = found.group(1).split()
            if words[0] in self._by["pred"]:
                return "(" + " ".join(self.atom(tuple(words))) + ")"
            if words[0] in self._by["action"] and len(words) - 1 == len(
                self._by["action"][words[0]].order
            ):
                return str(self.action(Action(words[0], tuple(words[1:]))))
            return found.group(0)

        return re.sub(r"\(([^\s()]+(?:\s+[^\s()]+)*)\s*\)", one, text)

    def _constants(self, args: Sequence[str]) -> tuple[str, ...]:
        to = dict(self.constants)
        return tuple(to.get(a, a) for a in args)


def user_actions(to_actions: Callable) -> Callable:
    """A domain's ``to_actions(problem, moves, strict)`` answering in the user's names when
    ``problem.renaming`` is set."""

    @functools.wraps(to_actions)
    def spoken(problem: Problem, moves: Sequence, strict: bool = True) -> tuple[Action, ...]:
        actions = tuple(to_actions(problem, moves, strict))
        if problem.renaming is None:
            return actions
        return tuple(problem.renaming.action(a) for a in actions)

    return spoken


def user_atoms(to_atoms: Callable) -> Callable:
    """A domain's ``to_atoms(problem, state)`` answering in the user's names when
    ``problem.renaming`` is set."""

    @functools.wraps(to_atoms)
    def spoken(problem: Problem, state) -> frozenset[Atom]:
        atoms = to_atoms(problem, state)
        if problem.renaming is None:
            return atoms
        return frozenset(problem.renaming.atom(a) for a in atoms)

    return spoken
