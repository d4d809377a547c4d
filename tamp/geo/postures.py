"""Other postures of the arm for a grasp whose pick or place collides: the IK branch as a choice.

The Panda has seven joints, so a hand pose is reached along a one-parameter family of arm
configurations (the elbow swings about the shoulder-wrist line, and with it the wrist's
knuckle, `panda_link6`, turns about the hand's axis). The pick-and-place planner takes the
member nearest the arm's configuration now (`motion.pick_place.plan_pick_place`), and that
is usually the posture with the knuckle towards the arm's base. Between tall towers that one
reaches into the tower in front of the hand while another posture of the same grasp passes
clear: traced on the cramped 20-block table, a block put down on the middle row behind a
5-block tower hit that tower's top block with link 6 (or link 5) in the nearest posture of
every top-down grasp, and 4 of 16 other postures of the first one lowered it clear.

`plan_postures` tries a grasp again in other postures, a seeded and so repeatable set:

1. the grasp and the place pose are solved from ``Tools.postures`` configurations around the
   arm's (Gaussian, `POSTURE_STD` rad per joint, the first seed the arm's own configuration),
   each on its seed's branch, in one batch (`motion.ik.IKSolver.from_seeds`);
2. each side keeps the distinct solutions whose arm stays clear along its straight lines,
   walked up on the solution's own branch (the open hand around the object on the descent to
   the grasp and on the lift from it, the held object on the lowering to the place; the
   guard's vertical margin): a posture that collides or leaves its branch there cannot pass
   the guard;
3. the pairs of a pick posture and a place posture are planned, the shortest joint path
   (arm to pick posture to place posture) first, up to `POSTURE_PAIRS`, skipping the pair of
   the nearest postures that already failed: each is planned with the pick's waypoints solved from
   its pick posture and the place's from its place posture
   (`plan_pick_place` ``seeds``), its vertical phases guarded first without the motion planner,
   then every phase by the guard as configured (a blocked approach or transit rerouted).

The first pair that passes is the move. None of this runs unless `tamp.geo.check.Tools` asks
for postures (``postures`` > 0) and the grasp failed with a collision; then for the first
`POSTURE_GRASPS` such grasps of the check's order only, which bounds what a move that no
posture saves costs.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from motion.guard import guard_pick_place, path_clear
from motion.ik import pose_yaw
from motion.pick_place import plan_pick_place, waypoint_targets
from motion.pick_place.lines import line_path

POSTURE_STD = 1.0  # rad per joint: the spread of the seeds about the arm's configuration
POSTURE_PAIRS = 6  # pick-and-place posture pairs per grasp, each planned at every transit height
POSTURE_GRASPS = 4  # colliding grasps of one check tried in other postures at most
SAME = 0.1  # rad (the largest joint's difference): two solutions of one pose are one posture
VERTICAL = ("descend", "lift", "lower", "retreat")


def posture_seeds(q, n: int, seed: int = 0) -> np.ndarray:
    """(n, J) configurations to solve a pose from: ``q`` itself, then ``n - 1`` Gaussian
    perturbations of it (`POSTURE_STD`), from a generator seeded with ``seed``."""
    q = np.asarray(q, dtype=np.float64)
    rng = np.random.default_rng(seed)
    return np.vstack([q[None], q + POSTURE_STD * rng.standard_normal((max(n - 1, 0), q.size))])


def _distinct(solutions: list[tuple[int, np.ndarray]]) -> list[tuple[int, np.ndarray]]:
    """The solutions (seed index, (J,)) that differ from every earlier one by more than
    `SAME` in some joint, in order."""
    kept: list[tuple[int, np.ndarray]] = []
    for k, q in solutions:
        if all(np.abs(q - other).max() > SAME for _, other in kept):
            kept.append((k, q))
    return kept


def _clear_lines(ends, lines, world, phase: str, tools) -> list:
    """The postures ``ends`` ((seed index, (J,)) at the common low end of ``lines``) whose arm
    stays clear along every straight line of ``lines`` ((4, 4) low end, (4, 4) high end)
    followed up on its own branch (`motion.pick_place.lines.line_path`), checked as the guard
    checks ``phase`` of the move in ``world`` (`motion.guard.path_clear`)."""
    step, out = tools.pick_place.vertical_step, []
    for k, q_end in ends:
        if not path_clear(q_end[None], tools.collision, world, phase, tools.guard):
            continue  # clear at its end first: no line walked for a posture that is not
        for low, high in lines:
            path = line_path(tools.solver, low, high, q_end, step)
            if path is None or not path_clear(path, tools.collision, world, phase, tools.guard):
                break
        else:
            out.append((k, q_end))
    return out


def clear_postures(world, request, tools, q, seed: int):
    """The distinct clear postures ((seed index, (J,)) lists) of the pick side at the grasp
    pose and of the place side at the place pose of ``request``, the move in ``world`` (a
    `motion.guard.PickPlaceWorld`; steps 1 and 2 of the module docstring): clear there and
    along the straight lines above, the descent and the lift for the pick (both as the
    descent is checked: the open hand around the object) and the lowering for the place."""
    solver = tools.solver
    hand = pose_yaw(solver.fk(q)[0])
    targets = waypoint_targets(request, hand, tools.pick_place)  # (6, 4, 4)
    pair = targets[[1, 4]]  # the grasp and the place
    starts = posture_seeds(q, tools.postures, seed)  # (S, J)
    s = len(starts)
    found = solver.from_seeds(np.repeat(pair, s, axis=0), np.tile(starts, (2, 1)))  # (2S,)
    picks = _distinct([(k, found.q[k].copy()) for k in range(s) if found.ok[k]])
    places = _distinct([(k, found.q[s + k].copy()) for k in range(s) if found.ok[s + k]])
    up = [(targets[1], targets[0]), (targets[1], targets[2])]  # the descent and the lift
    picks = _clear_lines(picks, up, world, "descend", tools)
    lower = [(targets[4], targets[3])]  # the lowering, from the place up
    places = _clear_lines(places, lower, world, "lower", tools) if picks else []
    tools.collision.hold(None)
    return picks, places


def plan_postures(world, requests, tools, q, seed: int = 0):
    """The guarded phases of one move with one grasp in another posture of the arm (see the
    module docstring), or None when no pair tried passes. ``world``: the guard's
    `motion.guard.PickPlaceWorld` of the move; ``requests``: its `PickPlaceRequest` at each
    transit height to try, lowest first (`tamp.geo.check.transit_heights`); ``q`` (J,): where
    the arm stands."""
    q = np.asarray(q, dtype=np.float64)
    quick = replace(tools.guard, plan=False)
    # the grasp and place poses do not depend on the transit height: screened once, up to
    # the lowest hover
    picks, places = clear_postures(world, requests[0], tools, q, seed)
    pairs = sorted(
        ((a, b) for a in picks for b in places if a[0] or b[0]),  # not the nearest pair
        key=lambda ab: np.linalg.norm(ab[0][1] - q) + np.linalg.norm(ab[1][1] - ab[0][1]),
    )[:POSTURE_PAIRS]
    for request in requests:
        for (_, pick), (_, place) in pairs:
            planned = plan_pick_place(
                tools.solver, q, request, tools.pick_place, seeds=(pick, place)
            )
            if not planned.ok:
                continue
            vertical = tuple(p for p in planned.phases if p.name in VERTICAL)
            if not guard_pick_place(vertical, tools.collision, world, quick, seed).ok:
                continue
            guarded = guard_pick_place(planned.phases, tools.collision, world, tools.guard, seed)
            if guarded.ok:
                return guarded.phases
    return None
