"""Other postures of the arm for a colliding grasp (`tamp.geo.postures`): the IK branch as a
choice in the geometric check the loop's fallback runs (`tamp.loop.geo_fallback.geo_check`)."""

from __future__ import annotations

import numpy as np
import pytest

from motion.guard import GuardConfig
from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.geo.postures import posture_seeds
from tamp.loop.execute import Placing
from tamp.loop.geo_fallback import geo_check, geo_tools
from tamp.obstacles import with_scene
from tamp.outcome import Failure
from tamp.scene import Pose, SceneConfig
from task.problem import TABLE, Move

CRAMPED = with_scene(SceneConfig(), "cramped")
S = CRAMPED.block_size
# the cramped 20-block table traced where every grasp's nearest posture hit a tower: a 5-block
# tower on the near slot in front of the place (0.56, -0.12), another beside it
STACKS = {
    (0.40, -0.12): "dcbli",
    (0.56, 0.12): "nskge",
    (0.40, 0.12): "oh",
    (0.72, -0.12): "prajqmf",
    (0.72, 0.12): "t",
}


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


def test_posture_seeds_start_at_the_arm_and_repeat():
    q = np.asarray(PANDA.q_home)
    seeds = posture_seeds(q, 5, seed=3)
    assert seeds.shape == (5, 7)
    np.testing.assert_array_equal(seeds[0], q)
    np.testing.assert_array_equal(seeds, posture_seeds(q, 5, seed=3))
    assert not np.array_equal(seeds, posture_seeds(q, 5, seed=4))


def test_another_posture_puts_a_block_down_behind_a_tower_the_nearest_one_hits(solver):
    """``h`` to the table behind a 5-block tower: in the arm's nearest posture every grasp
    collides; with postures the check passes in another posture of a top-down grasp, its
    phases starting where the arm stands."""
    from robots.collision import PandaCollision

    poses = {
        x: Pose((xy[0], xy[1], S / 2 + k * S), 0.0)
        for xy, tower in STACKS.items()
        for k, x in enumerate(tower)
    }
    move, target, q = Move("h", TABLE), Pose((0.56, -0.12, S / 2)), np.asarray(PANDA.q_home)
    placing = Placing(move, target, poses, CRAMPED)
    with PandaCollision(0.01) as model:
        plain = geo_tools(solver, model, GuardConfig(), postures=0)
        _, _, nearest = geo_check(placing, plain, q)
        assert not nearest.ok and nearest.failure is Failure.COLLISION
        assert all(t.failure is not None for t in nearest.tried)
        tools = geo_tools(solver, model, GuardConfig(), postures=16)
        _, _, other = geo_check(placing, tools, q)
    assert other.ok and other.evidence == {"posture": True}
    assert other.grasp.name.startswith("top")
    assert other.tried[-1].where == "posture" and other.tried[-1].failure is None
    np.testing.assert_allclose(other.motion[0].trajectory.positions[0], q)
    lower = next(p for p in other.motion if p.name == "lower").trajectory.positions[-1]
    at = solver.fk(lower)[0, :3, 3]  # the TCP at the release: the block's centre, raised
    np.testing.assert_allclose(at[:2], (0.56, -0.12), atol=1e-3)
    assert at[2] == pytest.approx(S / 2 + tools.pick_place.place_gap, abs=2e-3)
