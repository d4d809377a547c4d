"""Seeded random blocksworld instances in the PlanBench style.

The initial state is a random set of towers; the goal is the ``on`` atoms of another random
configuration (a partial goal, as in PlanBench: blocks that end on the table are left free),
optionally subsampled, and never already satisfied at init. Randomness comes only from
``random.Random(seed)``; nothing is seeded globally. The problems are relational (each block's
support); `task.domains.blocksworld_pddl.write_instances` writes them as PDDL files.
"""

from __future__ import annotations

import itertools
import random
import string

from task.errors import ProblemError
from task.problem import TABLE, Problem

_MAX_TRIES = 10_000
DOMAIN = "blocksworld"  # the domain of the problems made here (`task.domains.blocksworld`)


def block_names(n_blocks: int) -> tuple[str, ...]:
    """``a, b, c, ...`` for up to 26 blocks, else ``b1 .. bN``."""
    if n_blocks <= len(string.ascii_lowercase):
        return tuple(string.ascii_lowercase[:n_blocks])
    return tuple(f"b{i}" for i in range(1, n_blocks + 1))


def random_towers(
    names: tuple[str, ...], rng: random.Random, n_towers: int | None = None
) -> tuple[str, ...]:
    """A random configuration: the support of each of ``names`` (in that order).

    Without ``n_towers`` each block (in shuffled order) starts a new tower or goes on a random
    tower top; with it, the shuffled blocks are cut into exactly ``n_towers`` towers.
    """
    order = list(names)
    rng.shuffle(order)
    if n_towers is None:
        towers: list[list[str]] = []
        for x in order:
            k = rng.randrange(len(towers) + 1)
            if k == len(towers):
                towers.append([x])  # a new tower on the table
            else:
                towers[k].append(x)
    else:
        cuts = [0, *sorted(rng.sample(range(1, len(order)), n_towers - 1)), len(order)]
        towers = [order[i:j] for i, j in itertools.pairwise(cuts)]
    support = {x: below for t in towers for below, x in zip([TABLE, *t], t, strict=False)}
    return tuple(support[x] for x in names)


def random_problem(n_blocks: int, seed: int, n_goal_atoms: int | None = None) -> Problem:
    """A random problem with ``n_blocks`` blocks and ``n_goal_atoms`` goal ``on`` atoms.

    ``n_goal_atoms=None`` keeps every ``on`` atom of the goal configuration (at least one).
    The goal never holds at init.
    """
    if n_blocks < 2:
        raise ProblemError(f"random_problem needs at least 2 blocks for an on-goal, got {n_blocks}")
    if n_goal_atoms is not None and not 1 <= n_goal_atoms <= n_blocks - 1:
        raise ProblemError(
            f"n_goal_atoms must be between 1 and {n_blocks - 1} for {n_blocks} blocks, "
            f"got {n_goal_atoms}"
        )
    rng = random.Random(seed)
    names = block_names(n_blocks)
    for _ in range(_MAX_TRIES):
        init = random_towers(names, rng)
        most = None if n_goal_atoms is None else rng.randint(1, n_blocks - n_goal_atoms)
        final = random_towers(names, rng, most)
        atoms = [(x, s) for x, s in zip(names, final, strict=True) if s != TABLE]
        if n_goal_atoms is not None:
            keep = set(rng.sample(range(len(atoms)), n_goal_atoms))
            atoms = [a for i, a in enumerate(atoms) if i in keep]
        support = dict(zip(names, init, strict=True))
        if atoms and any(support[x] != y for x, y in atoms):
            name = f"BW-gen-{n_blocks}-{seed}"
            return Problem(name, DOMAIN, names, init, tuple(atoms))
    raise ProblemError(f"no goal found for {n_blocks} blocks after {_MAX_TRIES} tries")
