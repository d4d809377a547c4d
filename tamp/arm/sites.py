"""The arm's IK at each pick and place point, solved once per cost source
(`tamp.arm.costs.ArmCosts`): a search prices thousands of states whose blocks stand on the same
few slots and heights, so most points repeat.
"""

from __future__ import annotations

import numpy as np
import torch

from motion.cost import site_solutions
from motion.ik import IKSolver


class SiteSolutions:
    """`motion.cost.site_solutions` from ``q_now`` ((J,)) with ``solver``, each point solved
    once: point (to the µm) -> (configuration (J,), reached)."""

    def __init__(self, solver: IKSolver, q_now: np.ndarray) -> None:
        self.solver, self.q_now = solver, q_now
        self._sites: dict[tuple, tuple[np.ndarray, bool]] = {}  # point -> `solve`'s answer

    def solve(self, picks, places) -> tuple[torch.Tensor, torch.Tensor]:
        """`motion.cost.site_solutions` of picks (P, N, 3) then places (P, Y, 3) from
        ``q_now``, each point solved once per source. One batched IK call for the points (to
        the µm) not solved before. The batched solver stops once every target of its batch has
        a solution, so a point's configuration can be another of its seeds' than it would be in
        another batch; whether it is reached is the same."""
        xyz = torch.cat([torch.as_tensor(picks), torch.as_tensor(places)], dim=1)
        points = xyz.detach().reshape(-1, 3).to(torch.float64).numpy()  # (B, 3)
        keys = [tuple(np.round(p, 6).tolist()) for p in points]
        new = list(dict.fromkeys(k for k in keys if k not in self._sites))  # unseen, in order
        if new:
            at = torch.tensor(new, dtype=torch.float64)[None]  # (1, M, 3)
            q, ok = site_solutions(self.solver, self.q_now, at, at[:, :0])
            for k, qk, okk in zip(new, q.numpy(), ok.tolist(), strict=True):
                self._sites[k] = (qk, bool(okk))
        found = [self._sites[k] for k in keys]
        q = torch.from_numpy(np.stack([f[0] for f in found]))  # (B, J)
        return q, torch.tensor([f[1] for f in found], dtype=torch.bool)
