"""The bijection between two domains' actions, predicates, types and constants, by structure.

`find` backtracks over the reference's actions (the most constrained first): each is paired with
a user action of the same arity, then with a permutation of that action's parameters, and its
precondition, add and delete lists are matched atom by atom to the user's lists, which fixes
the predicate renaming (with each predicate's argument order), the type renaming and the
constant renaming as it goes. Atoms are compared as shapes over parameter positions, never by
name. ``budget`` allows that many *defects*: a reference atom the user's list lacks, or a user
atom the reference lacks; a match with one defect is a near miss, which `Defect` explains.
Sizes are small (at most a handful of actions of arity up to 5), so plain backtracking is fast.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

from task.domains.match.renaming import Renamed, Renaming
from task.domains.match.schema import LISTS, OBJECT, Pattern, Schema, Shape


@dataclass(frozen=True)
class Defect:
    """One difference: in the user's action ``user`` (paired with reference action ``reference``),
    list ``where`` (an index of `schema.LISTS`) lacks the reference pattern ``missing`` (its
    terms are reference parameter positions) or has the user pattern ``extra``."""

    user: Schema
    reference: Schema
    where: int
    order: tuple[int, ...]  # user parameter j is reference parameter order[j]
    missing: Pattern | None = None
    extra: Pattern | None = None


@dataclass(frozen=True)
class _Bound:
    """The renaming found so far (reference name -> user name and order)."""

    actions: tuple[tuple[str, str, tuple[int, ...]], ...] = ()
    preds: dict = field(default_factory=dict)  # reference -> (user, order)
    types: dict = field(default_factory=dict)  # reference -> user
    consts: dict = field(default_factory=dict)  # reference -> user
    defects: tuple[Defect, ...] = ()

    def bind(self, table: str, key: str, value) -> _Bound | None:
        """With ``key -> value`` added to ``table`` (kept injective); None when it clashes."""
        known = getattr(self, table)
        if key in known:
            return self if known[key] == value else None
        if value in known.values():
            return None
        return replace(self, **{table: {**known, key: value}})


def _bind_types(bound: _Bound, pairs) -> _Bound | None:
    for ref, user in pairs:
        bound = bound.bind("types", ref, user)
        if bound is None:
            return None
    return bound


def _term(bound: _Bound, ref: object, user: object) -> _Bound | None:
    """Reference term ``ref`` against user term ``user`` (positions already translated to the
    reference's): equal positions, or constants bound to each other."""
    if isinstance(ref, int) or isinstance(user, int):
        return bound if ref == user else None
    return bound.bind("consts", ref, user)


def _unify(bound: _Bound, ref: Pattern, user: Pattern, ref_shape: Shape, user_shape: Shape):
    """Every way reference atom ``ref`` is user atom ``user`` (terms in reference positions)."""
    arity = len(ref) - 1
    known = bound.preds.get(ref[0])
    if known is not None:
        orders = [known[1]] if known[0] == user[0] else []
    elif user[0] in {u for u, _ in bound.preds.values()}:
        orders = []
    else:
        orders = list(itertools.permutations(range(arity)))
    ref_types = dict(ref_shape.predicates).get(ref[0], (OBJECT,) * arity)
    user_types = dict(user_shape.predicates).get(user[0], (OBJECT,) * arity)
    for order in orders:
        out = bound
        for j, i in enumerate(order):
            out = None if out is None else _term(out, ref[1 + i], user[1 + j])
        if out is None:
            continue
        if known is None:
            out = _bind_types(out, ((ref_types[i], user_types[j]) for j, i in enumerate(order)))
            out = None if out is None else out.bind("preds", ref[0], (user[0], order))
        if out is not None:
            yield out


def _lists(
    bound: _Bound,
    pairs: list[tuple[list[Pattern], list[Pattern]]],
    budget: int,
    context: tuple[Schema, Schema, tuple[int, ...]],
    shapes: tuple[Shape, Shape],
    where: int = 0,
) -> Iterator[_Bound]:
    """Match each (reference list, user list) pair of ``pairs`` in turn."""
    if not pairs:
        yield bound
        return
    (refs, users), rest = pairs[0], pairs[1:]
    user, ref, order = context
    if not refs:
        if len(bound.defects) + len(users) > budget:
            return
        extra = tuple(Defect(user, ref, where, order, extra=u) for u in users)
        done = replace(bound, defects=bound.defects + extra)
        yield from _lists(done, rest, budget, context, shapes, where + 1)
        return
    first, later = refs[0], refs[1:]
    for k, candidate in enumerate(users):
        if len(candidate) != len(first):
            continue
        for out in _unify(bound, first, candidate, *shapes):
            left = [(later, users[:k] + users[k + 1 :]), *rest]
            yield from _lists(out, left, budget, context, shapes, where)
    if len(bound.defects) < budget:
        lack = replace(bound, defects=(*bound.defects, Defect(user, ref, where, order, first)))
        yield from _lists(lack, [(later, users), *rest], budget, context, shapes, where)


def _in_reference_positions(atoms: frozenset[Pattern], inverse: tuple[int, ...]) -> list:
    """User patterns with parameter ``j`` renumbered to the reference's ``inverse[j]``."""
    out = [(a[0], *(inverse[t] if isinstance(t, int) else t for t in a[1:])) for a in atoms]
    return sorted(out, key=repr)


def _pairs(bound: _Bound, ref: Schema, user: Schema, budget: int, shapes) -> Iterator[_Bound]:
    """Every way ``user`` is ``ref``: a parameter permutation, then the three lists."""
    gap = sum(abs(len(a) - len(b)) for a, b in zip(ref.lists, user.lists, strict=True))
    if len(ref.params) != len(user.params) or len(bound.defects) + gap > budget:
        return
    for perm in itertools.permutations(range(len(ref.params))):  # ref i -> user perm[i]
        typed = _bind_types(bound, ((ref.types[i], user.types[perm[i]]) for i in range(len(perm))))
        if typed is None:
            continue
        inverse = [0] * len(perm)
        for i, j in enumerate(perm):
            inverse[j] = i
        lists = [
            (sorted(r, key=repr), _in_reference_positions(u, tuple(inverse)))
            for r, u in zip(ref.lists, user.lists, strict=True)
        ]
        context = (user, ref, tuple(inverse))
        for out in _lists(typed, lists, budget, context, shapes):
            yield replace(out, actions=(*out.actions, (ref.name, user.name, tuple(inverse))))


def _hierarchy_ok(bound: _Bound, ref: Shape, user: Shape) -> bool:
    """Mapped types keep their parents: a reference root stays a root (or under unmapped user
    types), a reference subtype's user type has the mapped parent."""
    mapped = set(bound.types.values())
    for ref_type, user_type in bound.types.items():
        parent = ref.parent(ref_type) if ref_type != OBJECT else None
        if parent is not None:
            if user.parent(user_type) != bound.types.get(parent):
                return False
            continue
        seen, up = set(), user.parent(user_type)
        while up is not None and up not in seen:
            if up in mapped:
                return False
            seen.add(up)
            up = user.parent(up)
    return True


def find(user: Shape, ref: Shape, budget: int = 0) -> tuple[Renaming, tuple[Defect, ...]] | None:
    """The first renaming under which ``user`` is ``ref`` with at most ``budget`` defects, and
    its defects; None if there is none."""
    if len(user.actions) != len(ref.actions):
        return None
    order = sorted(ref.actions, key=lambda s: (-len(s.params), -sum(map(len, s.lists)), s.name))
    shapes = (ref, user)

    def assign(k: int, bound: _Bound, used: frozenset[str]) -> Iterator[_Bound]:
        if k == len(order):
            if _hierarchy_ok(bound, ref, user):
                yield bound
            return
        for candidate in user.actions:
            if candidate.name in used:
                continue
            for out in _pairs(bound, order[k], candidate, budget, shapes):
                yield from assign(k + 1, out, used | {candidate.name})

    for bound in assign(0, _Bound(), frozenset()):
        actions = tuple(Renamed(r, u, o) for r, u, o in sorted(bound.actions))
        preds = tuple(Renamed(r, u, o) for r, (u, o) in sorted(bound.preds.items()))
        renaming = Renaming(
            ref.name,
            user.name,
            actions,
            preds,
            tuple(sorted(p for p in bound.types.items() if p != (OBJECT, OBJECT))),
            tuple(sorted(bound.consts.items())),
        )
        return renaming, bound.defects
    return None


def explain(defect: Defect, renaming: Renaming) -> str:
    """``action 'grab': its delete list lacks (handempty)``, in the user's names where known."""
    params = defect.user.params
    if defect.extra is not None:
        # extra: terms are already reference positions; back to the user's parameters
        words = [defect.extra[0]]
        words += [
            f"?{params[defect.order.index(t)]}" if isinstance(t, int) else t
            for t in defect.extra[1:]
        ]
        where = f"action {defect.user.name!r}: its {LISTS[defect.where]}"
        return f"{where} has an extra ({' '.join(words)})"
    atom = defect.missing
    terms = tuple(
        f"?{params[defect.order.index(t)]}" if isinstance(t, int) else t for t in atom[1:]
    )
    known = {r.reference for r in renaming.predicates}
    text = renaming.atom((atom[0], *terms)) if atom[0] in known else (atom[0], *terms)
    hint = "" if atom[0] in known else f" (the reference's {atom[0]}, used nowhere else)"
    return f"action {defect.user.name!r}: its {LISTS[defect.where]} lacks ({' '.join(text)}){hint}"
