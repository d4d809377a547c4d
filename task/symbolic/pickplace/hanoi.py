"""Tower of Hanoi as a pick-and-place problem: seeded problems of the embedded domain.

The domain (`task/data/hanoi.pddl`, ``hanoi-pick-place``) has discs ``d1 .. dN`` (``d1`` the
smallest) and three pegs ``peg1 peg2 peg3``, regions on the table a disc is placed in. One
action, ``move ?d ?from ?to``, carries the top disc ``?d`` onto a clear disc or peg ``?to``
that is larger: ``(smaller ?d ?to)`` is static, true of every smaller disc and of every peg.

A problem puts every disc in one tower on a start peg and asks for the tower on another peg,
both pegs drawn from ``random.Random(seed)``; its optimal plan has ``2**N - 1`` moves
(`optimal_length`). With ``scattered`` the discs start on random pegs instead (each peg's discs
stacked by size), and the optimum is no longer that formula. `BINDING` binds ``move`` to the
motion layer (`task.symbolic.pickplace.binding`): object ``?d``, target ``?to``.
"""

from __future__ import annotations

import random

from task.errors import ProblemError

DOMAIN_FILE = "hanoi.pddl"  # in task.data
DOMAIN = "hanoi-pick-place"
PEGS = ("peg1", "peg2", "peg3")
MAX_DISCS = 10  # 2**10 - 1 moves already; the canonical problems have 3 to 5 discs
BINDING = """{
  "domain": "hanoi-pick-place",
  "actions": {"move": {"role": "move", "object": "?d", "target": "?to"}}
}"""


def disc_names(n_discs: int) -> tuple[str, ...]:
    """``d1 .. dN``, smallest first."""
    return tuple(f"d{i}" for i in range(1, n_discs + 1))


def domain_text() -> str:
    """The embedded Hanoi domain's PDDL text."""
    from task import data  # task.data parses with task.symbolic; imported when asked

    return data.read_text(DOMAIN_FILE)


def optimal_length(n_discs: int) -> int:
    """The optimal number of moves from one full tower to another: ``2**N - 1``."""
    return 2**n_discs - 1


def _stack(discs: list[str], peg: str) -> list[str]:
    """The ``on`` atoms of ``discs`` stacked by size on ``peg`` (largest at the bottom)."""
    order = sorted(discs, key=lambda d: -int(d[1:]))
    below = [peg, *order]
    return [f"(on {d} {s})" for d, s in zip(order, below, strict=False)]


def problem_text(n_discs: int, seed: int, scattered: bool = False) -> str:
    """The PDDL text of a seeded Hanoi problem with ``n_discs`` discs (see the module
    docstring); ProblemError for a count outside 1..MAX_DISCS."""
    if not 1 <= n_discs <= MAX_DISCS:
        raise ProblemError(f"hanoi needs 1 to {MAX_DISCS} discs, got {n_discs}")
    rng = random.Random(seed)
    discs = disc_names(n_discs)
    start, goal = rng.sample(PEGS, 2)
    where = {d: rng.choice(PEGS) for d in discs} if scattered else dict.fromkeys(discs, start)
    if all(p == goal for p in where.values()):
        where[discs[-1]] = start  # the goal must not hold at the start
    init = [a for peg in PEGS for a in _stack([d for d in discs if where[d] == peg], peg)]
    tops = {peg: [d for d in discs if where[d] == peg] for peg in PEGS}
    clear = [min(ds, key=lambda d: int(d[1:])) if ds else peg for peg, ds in tops.items()]
    smaller = [f"(smaller {a} {b})" for i, a in enumerate(discs) for b in discs[i + 1 :]]
    smaller += [f"(smaller {d} {peg})" for d in discs for peg in PEGS]
    name = f"hanoi-{n_discs}-{seed}" + ("-scattered" if scattered else "")
    lines = [
        f"(define (problem {name}) (:domain {DOMAIN})",
        f"  (:objects {' '.join(discs)} - disc {' '.join(PEGS)} - peg)",
        "  (:init",
        *(f"    {a}" for a in init),
        *(f"    (clear {x})" for x in clear),
        *(f"    {a}" for a in smaller),
        "  )",
        f"  (:goal (and {' '.join(_stack(list(discs), goal))})))",
    ]
    return "\n".join(lines) + "\n"
