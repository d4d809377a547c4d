"""`tamp bench motion`'s IK figures: the batched call on random targets and a move's six
waypoints in one call, every one solved."""

from __future__ import annotations

from motion.ik import IKSolver
from tamp.bench.motion import time_ik


def test_time_ik_times_a_moves_six_waypoints_and_solves_them():
    out = time_ik(IKSolver(), n=10, seed=1, moves=4)
    assert out["n"] == 10 and out["converged"] == 10
    assert out["moves"] == 4 and out["moves_solved"] == 4
    assert out["waypoints_median_s"] > 0.0 and out["time_s"] > 0.0
