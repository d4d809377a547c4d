"""The closed loop's Blocksworld world as a geometric scene: where `tamp.loop` calls on the
geometric TAMP room (`tamp.geo`).

The loop moves same-size cubes top-down onto blocks and table slots (`tamp.loop.execute`).
Where that fails the geometric room has more to offer: grasps and approaches as choices (side
and tilted grasps, a tower's top reachable whenever some approach reaches it) and transits at
the heights the corridor between pick and place needs instead of over the highest stack, each
phase guarded and a blocked free-space phase rerouted by the motion planner. The table stays
the loop's: a block goes where the loop would put it (onto a block, or onto its table slot),
so the scene's few slots stay the constraint they are. This module translates:

- `world_scene`: the observed block poses on a `tamp.scene.SceneConfig` table as a
  `tamp.world.schema.Scene` (`tamp.world.convert.from_poses.loop_scene`, the scene the loop's
  state is read from); each block's height is snapped to its level in the observed state, so
  the geometric checks, which read facts at a scene file's tight tolerances, read the state
  the loop read at its looser ones;
- `blocks_goal`: a Blocksworld goal as the scene goal (``on`` / ``ontable`` atoms);
- `geo_check`: one loop move checked over every grasp family, and a colliding grasp in other
  postures of the arm (`POSTURES`), without running it (the loop's motion check of a planned
  move, `tamp.loop.execute.motion_check`);
- `run_geo`: one loop move checked (every grasp family, blocked free-space phases rerouted) and run
  through `tamp.geo.check.check_move` and `tamp.geo.execute.run_move` in the loop's simulator,
  its outcome as the loop's `tamp.loop.execute.ExecutionResult` (the failure kinds are
  `tamp.outcome.Failure`'s, the same in both rooms);
- `GeoFallback`: the two as the loop executor's `tamp.loop.execute.Fallback`, which the episode
  builds (`geo_fallback`) and gives the executor: `tamp.loop.execute` imports nothing of this
  module or of `tamp.geo`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from motion.grasps import FAMILIES
from tamp.outcome import Failure
from tamp.scene import Pose, SceneConfig, towers
from tamp.sim.harness import Harness
from tamp.world.convert.from_poses import loop_scene, read_state
from task.problem import TABLE, Problem

if TYPE_CHECKING:
    from tamp.geo.check import Tools
    from tamp.loop.execute import ExecConfig, ExecutionResult, Placing
    from tamp.world.goal import Goal
    from tamp.world.schema import Scene

CHOICES = FAMILIES  # the grasp families the loop's geometric moves try: every one
# the order they are tried in (each family in `tamp.geo.check.grasp_order`): side grasps last,
# as the open fingers of a side grasp beside a block on the table reach the table top (a
# 7-block tower's top moved to a near slot: the side grasp touched the table for 137 physics
# steps, the tilted one touched nothing)
FAMILY_RANK = {"top": 0, "tilt": 1, "side": 2}
# seeds of other arm postures the loop's geometric moves try a colliding grasp in
# (`tamp.geo.postures`): on the cramped table a block put down behind a 5-block tower cleared
# it in 4 of 16 other postures of a top-down grasp, where the nearest posture of every grasp
# hit the tower
POSTURES = 16


def world_scene(entities: Sequence[str], poses: Mapping[str, Pose], scene: SceneConfig) -> Scene:
    """The blocks ``entities`` observed at ``poses`` on ``scene``'s table as a geometric scene
    (`tamp.world.convert.from_poses.loop_scene`: each block its solid, the scene's fixed boxes as
    obstacles, its slot grid). When the loop's reader reads a state from the poses, each block
    stands exactly on what it was read on (the geometric checks read the scene with a file's
    tight tolerances, not the loop's)."""
    world = loop_scene(entities, poses, scene)
    reading = read_state(entities, poses, scene)
    if reading.state is None:
        return world
    objects = {o.name: o for o in world.objects}
    for tower in towers(entities, reading.state):
        bottom = 0.0
        for x in tower:
            o = objects[x]
            xyz = (o.pose.xyz[0], o.pose.xyz[1], bottom + o.half[2])
            objects[x] = replace(o, pose=Pose(xyz, o.pose.yaw))
            bottom += 2 * o.half[2]
    return replace(world, objects=tuple(objects[x] for x in entities))


def blocks_goal(problem: Problem) -> Goal:
    """``problem``'s goal (block -> support) as ``on`` / ``ontable`` atoms."""
    from tamp.world.goal import Goal

    return Goal(tuple(("ontable", x) if y == TABLE else ("on", x, y) for x, y in problem.goal))


def geo_tools(
    solver, collision, guard, plan: bool = True, choices=CHOICES, postures: int = POSTURES
) -> Tools:
    """`tamp.geo.check.Tools` over the loop's IK solver and collision model (not closed by the
    loop's `Episode.close` twice: do not call its ``close``); ``plan``: reroute blocked
    free-space phases with the motion planner; ``postures``: seeds of the other arm postures
    a colliding grasp is tried in (`tamp.geo.postures`)."""
    from tamp.geo.check import Tools

    return Tools(
        solver,
        collision,
        guard=replace(guard, plan=plan),
        choices=tuple(choices),
        postures=postures,
    )


def geo_check(placing: Placing, tools: Tools, q_now, seed: int = 0):
    """``placing`` (a move to its target pose among the observed blocks) checked over every
    grasp family of ``tools`` from the arm at ``q_now``, nothing run: ``(world, geo move,
    verdict)`` (a `tamp.geo.check.MoveCheck`), what `run_geo` runs when the verdict passes."""
    from tamp.geo.check import candidate_grasps, check_move, grasp_order
    from tamp.geo.types import GeoMove, Place

    move, target, poses, scene = placing.move, placing.target, placing.poses, placing.scene

    world = world_scene(tuple(poses), poses, scene)
    name = "table" if move.target == TABLE else f"on.{move.target}"
    place = Place(name, move.target, tuple(float(v) for v in target.xyz), float(target.yaw))
    geo = GeoMove(move.entity, place)
    o = world.object(move.entity)
    grasps = grasp_order(world, o, candidate_grasps(o, tools.choices))
    grasps = tuple(sorted(grasps, key=_family_rank))
    verdict = check_move(world, geo, tools, grasps=grasps, q_now=q_now, seed=seed)
    return world, geo, verdict


def run_geo(
    sim,
    placing: Placing,
    tools: Tools,
    config: ExecConfig,
    seed: int = 0,
    harness: Harness = Harness(),
    observe: Callable[[], Mapping[str, Pose]] | None = None,
):
    """Check ``placing`` (a move to ``placing.target``, the pose the loop places the block at)
    over every grasp family of ``tools`` from the arm's configuration now, and run it when a
    grasp passes: the loop's `tamp.loop.execute.ExecutionResult` (``evidence`` names the
    grasp, or the geometric failure). ``config``: the loop's `ExecConfig` (the place check's
    tolerances); ``harness``: the fault injected and the recorders (`tamp.sim.harness.Harness`);
    ``observe``: the block poses after the run (default: the simulator's sensor
    is not read here, so the place is not checked)."""
    from tamp.geo.execute import RunConfig, rests_of, run_move
    from tamp.loop.execute import ExecutionResult

    wall0, sim0 = time.perf_counter(), sim.time
    move, poses, scene = placing.move, placing.poses, placing.scene
    world, geo, verdict = geo_check(placing, tools, sim.arm_q(), seed)

    def result(failure: Failure | None, run=None, **evidence) -> ExecutionResult:
        return ExecutionResult(
            move,
            failure is None,
            failure,
            {"geo": "ok" if failure is None else failure.value, **evidence},
            sim_time_s=sim.time - sim0,
            wall_time_s=time.perf_counter() - wall0,
            check_time_s=verdict.time_s,
            path_rad=0.0 if run is None else run.path_rad,
        )

    if not verdict.ok:
        tried = [f"{t.grasp}:{t.failure.value}" for t in verdict.tried]
        sides = sorted({t.side for t in verdict.tried if t.side})  # "pick", "place"
        return result(verdict.failure, tried=tried, sides=sides)
    below = next((x for x, p in poses.items() if _on(p, poses[move.entity], scene)), TABLE)
    rests = rests_of(world, geo, below)
    run = run_move(sim, geo, verdict, rests, RunConfig(), harness)
    # the grasp, and whether it passed in another posture of the arm (`tamp.geo.postures`)
    held = {
        "grasp": verdict.grasp.name,
        **({"posture": True} if verdict.evidence.get("posture") else {}),
    }
    if not run.ok:
        return result(run.failure, run, **held, **run.evidence)
    if observe is None:
        return result(None, run, **held)
    seen = observe()[move.entity]
    dxy = float(np.linalg.norm(seen.xy - np.asarray(geo.place.xyz[:2])))
    dz = abs(seen.xyz[2] - geo.place.xyz[2])
    if dxy > config.place_tol_xy or dz > config.place_tol_z:
        out = result(None, run, **held, off_xy_m=round(dxy, 4), off_z_m=round(dz, 4))
        return replace(out, ok=False, failure=Failure.MISPLACED)
    return result(None, run, **held)


@dataclass(frozen=True)
class GeoFallback:
    """The geometric room as the loop executor's `tamp.loop.execute.Fallback`: `geo_check`
    and `run_geo` over ``tools`` (`geo_tools`)."""

    tools: Tools

    def check(self, placing: Placing, q_now, seed: int = 0) -> bool:
        """Whether `geo_check` passes ``placing`` from the arm at ``q_now``."""
        return geo_check(placing, self.tools, q_now, seed)[2].ok

    def run(
        self,
        sim,
        placing: Placing,
        config: ExecConfig,
        seed: int = 0,
        drop_at: float | None = None,
        observe: Callable[[], Mapping[str, Pose]] | None = None,
    ) -> ExecutionResult:
        """`run_geo` of ``placing`` in ``sim``, ``drop_at`` its fault (`Harness`)."""
        harness = Harness(drop_at=drop_at)
        return run_geo(sim, placing, self.tools, config, seed, harness, observe)


def geo_fallback(solver, collision, guard) -> GeoFallback:
    """The loop executor's geometric fallback over its IK ``solver`` and ``collision`` model,
    blocked free-space phases rerouted (``guard``: the executor's `GuardConfig`)."""
    return GeoFallback(geo_tools(solver, collision, guard, plan=True))


def _family_rank(grasp) -> int:
    """`FAMILY_RANK` of ``grasp`` by its name's family (``top0``, ``tilt+x``, ``side-y:flip``)."""
    return next((r for f, r in FAMILY_RANK.items() if grasp.name.startswith(f)), len(FAMILY_RANK))


def _on(below: Pose, above: Pose, scene: SceneConfig) -> bool:
    """Whether a block at ``above`` stands on one at ``below`` (the loop's reader's test)."""
    near = np.linalg.norm(above.xy - below.xy) <= scene.tol_xy
    return bool(near and abs(above.xyz[2] - below.xyz[2] - scene.block_size) <= scene.tol_z)
