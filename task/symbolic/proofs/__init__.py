"""task.symbolic.proofs: proofs that a STRIPS problem has no plan, told apart from a planner
that ran out of budget.

- ``proof``: the `Proof` value and `prove_unsolvable`, which tries the proofs cheapest first;
- ``mutex``: h^2 reachability (pairs of atoms that never hold together) and the acyclicity
  invariant of a binary predicate that it supports (a Blocksworld goal cycle);
- ``exhaust``: breadth-first search over every reachable ground state, under a state cap.

Each proof is sound: ``unsolvable`` is True only when no plan exists. Like the rest of the
crisp side, nothing here imports torch or a domain.
"""

from task.symbolic.proofs.proof import Proof, prove_unsolvable

__all__ = ["Proof", "prove_unsolvable"]
