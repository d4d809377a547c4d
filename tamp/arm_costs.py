"""The arm's cost of every candidate move, for motion-aware task planning (`task.costs`).

`ArmCosts` is a `task.costs.CostSource` for Blocksworld problems laid out on a table scene.
For a window starting in a crisp state it predicts where every block stands (blocks keep their
observed places; a tower moved to the table stands on a free slot, `predict_poses`), then prices
each move x -> y with `motion.cost.move_costs`: the joint-space distance between the grasp
configuration at x and the release configuration on y (through pytorch-kinematics, with
gradients to the targets), plus the reach residual, an infeasibility penalty and the sphere
model's clearance to the scene's obstacles along the move and to the other blocks (boxes at
their predicted places) at its grasp and release. A place onto a tower that its slot's
clearance cannot take (`tamp.scene.SceneConfig.capacity`: a shelf over it), a move to a full
table and a grasp or release reaching `DEEP` into another block get ``blocked`` on top, and so
does a move the arm failed in that state before (``avoid``, `failed_key`) or, in any state,
where it failed (``failed``, `FailedMove`: picked and put among the same blocks). Each point's
IK is solved once per source (`ArmCosts._site_solutions`). With ``grasps`` (the executor's
geometric fallback, `tamp.loop.geo_fallback`: tilted and side grasps, corridor transits) the
prices agree with what that executor can do: a pick or place out of top-down reach that one of
those grasps reaches, and a top-down grasp or release into a neighbour, cost `DETOUR` instead.
The matrix is computed once per state: the table placement is the scene's free slot, or with
table places (`tamp.slots`) each place's centre. With ``reach`` > 0 the places move (continuous
placements): every window optimises fresh offsets, one set per restart row, with the logits, and
the source records, for each committed move, the position the chosen row decided it with
(`ArmCosts.decided`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import torch

from motion.cost import (
    Blocks,
    Bodies,
    MoveCostConfig,
    block_depths,
    move_costs_batch,
    site_solutions,
)
from motion.ik import IKSolver
from motion.pick_place import PickPlaceConfig
from tamp.scene import (
    XY,
    PlacedMove,
    Pose,
    SceneConfig,
    free_slot,
    plain_move,
    towers,
)
from tamp.world.convert.from_poses import read_state
from task.costs import IMPOSSIBLE, CostSourceBase
from task.domains.base import State
from task.problem import TABLE, Move, Problem

# the move cost with the sphere model's clearance to the scene's obstacles (weight 5 per m of
# CHOMP cost: 0.2-0.9 for a move sweeping past clutter's posts, next to about 1 per move of
# joint distance; `motion.cost`), and to the other blocks at the grasp and the release
ARM = MoveCostConfig(collision_weight=5.0, block_weight=5.0)
# m: a grasp or release configuration whose spheres reach deeper into another block is BLOCKED
# (the executor passes through it). Small, as the spheres under-cover the guard's convex hull
# of panda_link5: in 60 random cramped layouts every sphere penetration was a hull collision,
# and 62 of the 82 hull collisions went deeper than 2 mm (1 cm: 16). Against the guard on
# whole moves (tower behind tower): 31 of 33 failing moves blocked, none of 159 sound ones
DEEP = 0.002
HOVER = PickPlaceConfig()  # the executor's hover and transit heights
BLOCKED = IMPOSSIBLE  # added to a move the scene cannot take: the planner refuses it
# added instead to a move the top-down grasp cannot make but the executor's other grasps may
# (`ArmCosts`' ``grasps``): about one move's joint distance, chosen, not tuned
DETOUR = 1.0
# m: the blocks around a pick or a place that a failed move's memory keeps (`Site`): within
# reach of the hand and the forearm over it (the next slot, not the diagonal one); how far a
# block may be from where it was recorded to still count as there (observation noise)
AROUND, SAME = 0.2, 0.015


def predict_poses(
    entities: Sequence[str],
    state: State,
    poses: Mapping[str, Pose],
    scene: SceneConfig,
    bases: Mapping[str, tuple[float, float]] | None = None,
) -> dict[str, Pose]:
    """Block poses after the plan reached ``state`` from the observed ``poses``: a block with
    the same blocks under it as observed keeps its observed pose; otherwise its tower keeps
    the base block's observed table position when that base was on the table, else it stands
    on a free slot, and the block stands exactly above the base. ``bases``: where each tower
    base stands (a planned table place, `tamp.slots`) instead."""
    s, out = scene.block_size, {}
    stacks = towers(entities, state)
    seen = read_state(entities, poses, scene).state
    before = (
        {}
        if seen is None
        else {x: tuple(t[:k]) for t in towers(entities, seen) for k, x in enumerate(t)}
    )
    grounded = [t for t in stacks if abs(poses[t[0]].xyz[2] - s / 2) <= scene.tol_z]
    if bases is not None:
        grounded = stacks
    for tower in grounded:
        base, stays = poses[tower[0]], True
        if bases is not None:  # moved onto its planned place unless it stands there already
            xy = bases[tower[0]]
            if before.get(tower[0]) != () or math.dist(base.xy, xy) > scene.slot_radius:
                base, stays = Pose((*xy, s / 2), 0.0), False
        for level, x in enumerate(tower):
            out[x] = Pose((base.xyz[0], base.xyz[1], s / 2 + level * s), base.yaw)
            if stays and before.get(x) == tuple(tower[:level]):
                out[x] = poses[x]  # nothing under it changed
    for tower in (t for t in stacks if t not in grounded):
        taken = {k: v for k, v in out.items()}
        slot = free_slot(taken, poses[tower[0]].xyz, scene) or scene.slots[0]
        for level, x in enumerate(tower):
            out[x] = Pose((slot[0], slot[1], s / 2 + level * s), 0.0)
    return out


class _Fixed:
    """The costs of one window: a fixed (P, N, Y) matrix, the same for every restart row, and
    no parameters (a move onto a table place goes to the place's centre)."""

    lr = 0.0

    def __init__(self, owner: ArmCosts, indices: Sequence[int], matrix: torch.Tensor) -> None:
        self.owner, self.indices, self.matrix = owner, list(indices), matrix

    def compute(self) -> torch.Tensor:
        return self.matrix  # (P, N, Y)

    def parameters(self) -> list[torch.Tensor]:
        return []

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        for i, done in zip(self.indices, moves, strict=True):
            self.owner._record(i, done, None)


class _Placed:
    """The costs of one window whose K table places move, per restart row: in row b (problem
    p = b // R, restart b % R) place k sits at its centre + ``reach * tanh(u[b, k])`` in x and
    y, u starting at 0 in every window. The IK solutions at the centres are reused
    (`motion.cost.site_solutions`), refined differentiably at every step. Row b's costs depend
    on u[b] only, so each restart row optimises its own placements."""

    lr = 0.05  # Adam learning rate of the unbounded offsets u

    def __init__(
        self, owner: ArmCosts, indices: Sequence[int], restarts: int, inputs, solved, extra
    ) -> None:
        picks, places, _, blocks = inputs
        q, ok = solved  # (P * (N + Y), J), (P * (N + Y),)
        p, r, n = picks.shape[0], restarts, picks.shape[1]
        self.owner, self.indices, self.restarts, self.n = owner, list(indices), r, n
        self.picks = picks.repeat_interleave(r, dim=0)  # (B, N, 3), B = P * R
        self.places = places.repeat_interleave(r, dim=0)  # (B, Y, 3)
        self.extra = extra.repeat_interleave(r, dim=0)  # (B, N, Y)
        self.solved = (
            q.reshape(p, -1, q.shape[-1]).repeat_interleave(r, dim=0).reshape(-1, q.shape[-1]),
            ok.reshape(p, -1).repeat_interleave(r, dim=0).reshape(-1),
        )  # (B * (N + Y), J), (B * (N + Y),)
        self.blocks = Blocks(*(t.repeat_interleave(r, dim=0) for t in blocks))
        k = places.shape[1] - n
        self.u = torch.zeros(p * r, k, 2, dtype=torch.float64, requires_grad=True)  # (B, K, 2)

    def shift(self) -> torch.Tensor:
        """(B, K, 2) m: every row's offset of every place from its centre."""
        return self.owner.reach * torch.tanh(self.u)

    def compute(self) -> torch.Tensor:
        o, n = self.owner, self.n
        table = self.places[:, n:] + torch.nn.functional.pad(self.shift(), (0, 1))  # (B, K, 3)
        places = torch.cat([self.places[:, :n], table], dim=1)  # (B, Y, 3)
        bodies = Bodies(o.boxes, self.blocks)
        c = move_costs_batch(o.solver, o.q_now, self.picks, places, o.config, bodies, self.solved)
        return c + self.extra  # (B, N, Y)

    def parameters(self) -> list[torch.Tensor]:
        return [self.u]

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        shift = self.shift().detach()  # (B, K, 2)
        for p, (i, row, done) in enumerate(zip(self.indices, rows, moves, strict=True)):
            self.owner._record(i, done, None if row is None else shift[p * self.restarts + row])


@dataclass(frozen=True)
class Arm:
    """The arm a plan is priced for, as its planner knows it now: the IK ``solver``, where it
    stands (``q_now``, (J,)), what its executor can do besides the top-down grasp over the
    highest stack (``grasps``: the grasp families of its geometric fallback, with which a pick
    or place only those reach is not ruled out, `ArmCosts`; ``check``: the executor's own check
    of a move among poses, `ArmCosts.verify`; None: none), and what it failed so far
    (``avoid``: plain state -> `failed_key`s of the moves that failed there; ``failed``: the
    moves it failed by where, ruled out wherever they would be the same, `FailedMove`)."""

    solver: IKSolver
    q_now: object
    grasps: tuple[str, ...] = ()
    check: Callable[[Mapping[str, Pose], Move], bool] | None = None
    avoid: Mapping[State, set] | None = None
    failed: Sequence[FailedMove] = ()


class ArmCosts(CostSourceBase):
    """`task.costs.CostSource` of Blocksworld ``problems`` whose blocks were observed at
    ``poses[k]`` (block -> `Pose`), priced for ``arm`` (`Arm`: the arm now at ``arm.q_now``,
    (J,)). ``places``: per problem, table place -> (x, y), for slotted problems (`tamp.slots`);
    ``reach``: how far a block may go from its place's centre (m; 0: the places are fixed)."""

    can_forget = True  # `forget` drops the moves committed for a problem

    def __init__(
        self,
        problems: Sequence[Problem],
        poses: Sequence[Mapping[str, Pose]],
        scene: SceneConfig,
        arm: Arm,
        config: MoveCostConfig = ARM,
        places: Sequence[Mapping[str, XY]] | None = None,
        reach: float = 0.0,
    ) -> None:
        self.problems, self.poses, self.scene = list(problems), list(poses), scene
        self.check = arm.check  # the executor's own check of a move among poses (`verify`)
        self._verified: dict[tuple[int, State, object], bool] = {}  # `verify`'s answers
        self._refused: dict[tuple[int, State], set] = {}  # moves `verify` ruled out there
        self.failed = tuple(arm.failed)  # moves the arm failed, by where (`FailedMove`)
        self.grasps = tuple(arm.grasps)  # grasp families the executor also has (`_hover`)
        self._reached: dict[tuple, bool] = {}  # (x, y, z mm, yaw) -> `_grasped`, per source
        self._sites: dict[tuple, tuple[np.ndarray, bool]] = {}  # point -> `_site_solutions`
        self.places = places  # per problem: table place -> (x, y), for slotted problems
        self.avoid = arm.avoid or {}  # plain state -> `failed_key`s of moves that failed there
        self.solver, self.q_now = arm.solver, np.asarray(arm.q_now, float)
        self.config = config
        self.reach = reach  # m: how far a block may go from its place's centre (0: fixed)
        self.boxes = obstacle_tensors(scene)  # the collision proxy's obstacles, made once
        self._cache: dict[tuple[int, State], torch.Tensor] = {}
        self._decided: dict[int, list[tuple[object, XY | None]]] = {}

    def verify(self, index: int, state: State, move) -> bool:
        """Whether the executor finds ``move``'s motion in ``state`` of problem ``index``
        (`task.costs.CostSourceBase`'s check ahead, `task.planner.windows.own_state_prefix`):
        ``check`` on the poses this source predicts there (`predict_poses`; a move onto a table
        place goes to its centre), the arm where it is now. A move it fails is ruled out in that
        state from then on (priced `BLOCKED`): the next window there decodes another. True
        without ``check``, and with moving places (``reach`` > 0: the place is not known yet).
        One check per (problem, state, move)."""
        if self.check is None or self.reach > 0:
            return True
        key = (index, state, move)
        if key not in self._verified:
            at, _, now = self._predicted(index, state)
            planned = move if at is None else plain_move(move, at)
            self._verified[key] = ok = bool(self.check(now, planned))
            if not ok:
                self._refused.setdefault((index, state), set()).add(move)
                self._cache.pop((index, state), None)
        return self._verified[key]

    def decided(self, index: int) -> list[tuple[object, XY | None]]:
        """Every move the planner committed for problem ``index`` since this source was made,
        in order, with the (x, y) of the table place it goes to as its window decided it: the
        place's centre plus the offset of the restart row the move came from (None: a move
        onto a block or, without places, onto the table)."""
        return list(self._decided.get(index, ()))

    def forget(self, index: int) -> None:
        """Drop the moves committed for problem ``index`` (the planner's fallback started its
        plan over from the initial state, `task.planner`)."""
        self._decided.pop(index, None)

    def _record(self, index: int, moves: Sequence, shift: torch.Tensor | None) -> None:
        """Note the committed ``moves`` of problem ``index`` with their places' positions
        (``shift``: (K, 2) offsets from the centres, None: at the centres)."""
        problem = self.problems[index]
        at = None if self.places is None else self.places[index]
        out = self._decided.setdefault(index, [])
        for move in moves:
            xy = None
            if at is not None and move.target in at:
                xy = at[move.target]
                if shift is not None:
                    dx, dy = shift[problem.fixed.index(move.target)].tolist()
                    xy = (xy[0] + dx, xy[1] + dy)
            out.append((move, xy))

    def __call__(self, indices: Sequence[int], states: Sequence[State], restarts: int = 1):
        """The costs of a window (`task.costs.CostSource`): a fixed (P, N, Y) matrix, or with
        places and ``reach`` > 0 per-row placements (P * ``restarts``, N, Y)."""
        if self.reach > 0 and self.places is not None:
            return self._placed(indices, states, restarts)
        todo = [(i, s) for i, s in zip(indices, states, strict=True) if (i, s) not in self._cache]
        if todo:
            for key, matrix in zip(todo, self._price(todo), strict=True):
                self._cache[key] = matrix
        keys = zip(indices, states, strict=True)
        return _Fixed(self, indices, torch.stack([self._cache[key] for key in keys]))

    def _placed(self, indices: Sequence[int], states: Sequence[State], restarts: int) -> _Placed:
        """A window whose table places move within ``reach`` of their centres: continuous
        placements, fresh for the window and one set per restart row, optimised with the
        logits."""
        *inputs, other = self._inputs(list(zip(indices, states, strict=True)))
        picks, places, extra, blocks = inputs
        solved = self._site_solutions(picks, places)
        extra = extra + self._deep(solved, blocks) + self._detour(solved, other, picks.shape[1])
        return _Placed(self, indices, restarts, inputs, solved, extra)

    def _price(self, todo: list[tuple[int, State]]) -> list[torch.Tensor]:
        """(N, Y) cost matrices of the (problem index, state) pairs, one batched IK call."""
        picks, places, extra, blocks, other = self._inputs(todo)
        solved = self._site_solutions(picks, places)
        with torch.no_grad():
            bodies = Bodies(self.boxes, blocks)
            c = move_costs_batch(
                self.solver, self.q_now, picks, places, self.config, bodies, solved
            )
        extra = extra + self._deep(solved, blocks) + self._detour(solved, other, picks.shape[1])
        return list(c + extra)  # (P, N, Y) each

    def _site_solutions(self, picks, places) -> tuple[torch.Tensor, torch.Tensor]:
        """`motion.cost.site_solutions` of picks (P, N, 3) then places (P, Y, 3) from
        ``q_now``, each point solved once per source: a search prices thousands of states whose
        blocks stand on the same few slots and heights, so most points repeat. One batched IK
        call for the points (to the µm) not solved before. The batched solver stops once every
        target of its batch has a solution, so a point's configuration can be another of its
        seeds' than it would be in another batch; whether it is reached is the same."""
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

    def _detour(self, solved, other: torch.Tensor, n: int) -> torch.Tensor:
        """(P, N, Y) ``DETOUR - config.infeasible`` per pick and per place whose top-down IK
        failed (priced `config.infeasible`, as much as `BLOCKED`) where another of the
        executor's grasps reaches (``other``: (P, N + Y) from `_hover`): the move stays open,
        at a detour's price. ``n``: N."""
        p, sites = other.shape
        failed = ~solved[1].reshape(p, sites)  # (P, N + Y)
        fix = (DETOUR - self.config.infeasible) * (failed & other).double()  # (P, N + Y)
        return fix[:, :n, None] + fix[:, None, n:]  # (P, N, Y)

    def _deep(self, solved, blocks: Blocks) -> torch.Tensor:
        """(P, N, Y) BLOCKED where the top-down grasp or release configuration reaches more than
        `DEEP` into a block other than the held one and the one under it (with the blocks
        priced). With ``grasps`` the executor tries its other grasps there, so such a move
        costs `DETOUR` more, not ruled out; once it failed it is (``avoid``)."""
        if self.config.block_weight == 0.0:
            return torch.zeros(())
        penalty = DETOUR if self.grasps else BLOCKED
        return penalty * (block_depths(self.solver, solved, blocks) > DEEP)

    def _predicted(self, index: int, state: State):
        """``(places, plain state, poses)`` of problem ``index`` in ``state``: its table
        places (None without), the state with every place read as the table, and the block
        poses predicted there (`predict_poses`, a tower on a place standing at its centre)."""
        problem = self.problems[index]
        at = None if self.places is None else self.places[index]
        plain = state if at is None else tuple(TABLE if x in at else x for x in state)
        bases = (
            None
            if at is None
            else {x: at[p] for x, p in zip(problem.entities, state, strict=True) if p in at}
        )
        return (
            at,
            plain,
            predict_poses(problem.entities, plain, self.poses[index], self.scene, bases),
        )

    def _inputs(self, todo: list[tuple[int, State]]):
        """Picks (P, N, 3), places (P, Y, 3), the added costs (P, N, Y) of the pairs, their
        blocks as boxes (a turned block as its axis-aligned bounding box) and (P, N + Y) the
        picks and places only the executor's other grasps reach (`_hover`)."""
        picks, places, extra, half, under, other = [], [], [], [], [], []
        s = self.scene.block_size
        for i, state in todo:
            problem = self.problems[i]
            at, plain, now = self._predicted(i, state)
            xyz = np.array([now[x].xyz for x in problem.entities])  # (N, 3)
            up = xyz + np.array([0.0, 0.0, s])  # onto each block
            if at is None:
                slot = free_slot(now, xyz.mean(0), self.scene)
                table = [(slot[0], slot[1], s / 2) if slot is not None else tuple(xyz.mean(0))]
            else:  # every place of the slotted problem, K = len(problem.fixed)
                table = [(*at[k], s / 2) for k in problem.fixed]
            picks.append(xyz)
            turn = [abs(math.cos(now[x].yaw)) + abs(math.sin(now[x].yaw)) for x in problem.entities]
            half.append([(r * s / 2, r * s / 2, s / 2) for r in turn])  # the bounding box
            under.append([problem.entities.index(b) if b != TABLE else -1 for b in plain])
            places.append(np.vstack([up, table]))  # (Y, 3), Y = N + K
            extra.append(self._blocked(problem, plain, now, at is None and slot is None))
            yaws = [now[x].yaw for x in problem.entities]
            other.append(self._hover(extra[-1], xyz, places[-1], now, yaws))
            for failed in self.failed:  # a move the arm failed where it would be the same
                j = failed.columns(problem.entities, now, places[-1])
                if j:
                    extra[-1][problem.entities.index(failed.entity), j] += BLOCKED
            for move in self._refused.get((i, state), ()):  # its check ahead failed here
                j = problem.targets.index(move.target)
                extra[-1][problem.entities.index(move.entity), j] += BLOCKED
            for x, key in self.avoid.get(plain, ()):  # a move the arm failed in this state
                j = _column(problem, key, at, self.reach)
                if j is not None:
                    extra[-1][problem.entities.index(x), j] += BLOCKED
        picks, places, extra = (torch.tensor(np.stack(a)) for a in (picks, places, extra))
        half, under = torch.tensor(half).reshape(picks.shape), torch.tensor(under, dtype=torch.long)
        blocks = Blocks(picks, half, under.reshape(picks.shape[:2]))
        return picks, places, extra, blocks, torch.tensor(np.stack(other))

    def _hover(self, extra: np.ndarray, picks: np.ndarray, places: np.ndarray, now, yaws):
        """Add BLOCKED (in place) to the moves whose pick or place the hand cannot reach from
        above: a pick-and-place hovers and carries the block over the highest stack top
        (`motion.pick_place`), where a far slot may be out of the arm's reach. One batched,
        detached IK call; the hand's yaw is taken as 0. With ``self.grasps``, a pick or place
        out of that reach stays open when one of those grasps holds the block there (`_grasped`,
        ``yaws``: (N,) the picked blocks' yaws; a place's is 0). Returns (N + Y,) bool: the
        picks and places only those grasps reach (`_detour`)."""
        top = max(p.xyz[2] for p in now.values()) + self.scene.block_size / 2
        hover = top + HOVER.lift_clearance + self.scene.block_size  # TCP holding a block
        points = np.vstack([picks, places])  # (N + Y, 3)
        points[:, 2] = np.maximum(points[:, 2], hover)
        n = picks.shape[0]
        ok = self._site_solutions(points[None, :n], points[None, n:])[1]
        ok = ok.numpy().copy()  # (N + Y,)
        other = np.zeros_like(ok)  # (N + Y,) out of that reach, in another grasp's
        if self.grasps and not ok.all():  # the executor's other grasps, at the block's height
            at = np.vstack([picks, places])[~ok]  # (M, 3)
            turned = np.concatenate([np.asarray(yaws, float), np.zeros(len(points) - n)])
            other[~ok] = self._grasped(at, turned[~ok])
        ok |= other
        extra[~ok[:n], :] += BLOCKED
        extra[:, ~ok[n:]] += BLOCKED
        return other

    def _grasped(self, points: np.ndarray, yaws: np.ndarray) -> np.ndarray:
        """(M,) whether some grasp of ``self.grasps`` (`motion.grasps.grasps` of a cube) holds
        a block centred at ``points`` (M, 3), turned ``yaws`` (M,), with the arm's IK solved:
        where the executor's geometric fallback (`tamp.loop.geo_fallback.run_geo`) may still pick or
        place it when no top-down grasp reaches over the highest stack. One batched IK call for
        the poses (to the mm and 0.01 rad) this source has not tested before."""
        from motion.grasps import world_tcp

        family = self._family
        if not family or len(points) == 0:
            return np.zeros(len(points), dtype=bool)
        keys = [
            (*np.round(p, 3).tolist(), round(float(y), 2))
            for p, y in zip(points, yaws, strict=True)
        ]
        new = list(dict.fromkeys(k for k in keys if k not in self._reached))  # unseen poses
        if new:
            targets = np.stack(
                [world_tcp(g, k[:3], k[3]) for k in new for g in family]
            )  # (M * G, 4, 4)
            found = np.asarray(self.solver.solve(targets, self.q_now).ok)
            for k, ok in zip(new, found.reshape(len(new), len(family)).any(1), strict=True):
                self._reached[k] = bool(ok)
        return np.array([self._reached[k] for k in keys], dtype=bool)

    @functools.cached_property
    def _family(self) -> tuple:
        """The grasps of ``self.grasps`` for a block of the scene (`motion.grasps.grasps` of a
        cube), made once."""
        from motion.grasps import grasps

        return grasps("cube", (self.scene.block_size / 2,) * 3, self.grasps)

    def _blocked(self, problem: Problem, state: State, now, table_full: bool) -> np.ndarray:
        """(N, Y) BLOCKED where the place has no room: a tower at its slot's capacity, or no
        free table slot."""
        n = problem.n
        out = np.zeros((n, len(problem.targets)))
        support = dict(zip(problem.entities, state, strict=True))
        for j, y in enumerate(problem.entities):
            height, below = 1, support[y]
            while below != TABLE:
                height, below = height + 1, support[below]
            if height + 1 > self.scene.capacity(now[y].xy):
                out[:, j] = BLOCKED
        if table_full:
            out[:, n:] = BLOCKED
        return out


@dataclass(frozen=True)
class Site:
    """A point of a move (where the hand picks a block, or where it would put one) with the
    blocks then within `AROUND` of it in (x, y): what a grasp or release there runs into."""

    xyz: tuple[float, float, float]
    around: tuple[tuple[str, tuple[float, float, float]], ...]  # (name, centre), by name

    @classmethod
    def at(cls, xyz, poses: Mapping[str, Pose], leave: str) -> Site:
        """The site of point ``xyz`` among the blocks at ``poses`` (name -> `Pose`) but
        ``leave`` (the block that moves)."""
        point = tuple(float(v) for v in xyz)
        around = tuple(
            (name, tuple(float(v) for v in p.xyz))
            for name, p in sorted(poses.items())
            if name != leave and math.dist(p.xyz[:2], point[:2]) <= AROUND
        )
        return cls(point, around)

    def matches(self, xyz, poses: Mapping[str, Pose], leave: str) -> bool:
        """Whether point ``xyz`` among ``poses`` is this site again, or one at least as
        crowded: the point and every block that was around it where they were (within
        `SAME`); a block come near since only adds to what the hand runs into."""
        if math.dist(xyz, self.xyz) > SAME:
            return False
        return all(
            name in poses and math.dist(poses[name].xyz, at) <= SAME for name, at in self.around
        )


@dataclass(frozen=True)
class FailedMove:
    """A move the arm failed, kept by where it failed (`ArmCosts`' ``failed``): moving
    ``entity`` from the ``pick`` site to the ``place`` site, or from the ``pick`` site to
    anywhere (``place`` None: the pick itself failed with every grasp, whatever the place).
    It is ruled out wherever both sites are the same again (or more crowded) and the stacks
    as high, in any state: the memory of the move in the state it failed in (``avoid``) holds
    in that state only."""

    entity: str
    pick: Site
    place: Site | None
    top: float  # m: the highest block's centre then (the top-down hand hovers over it)

    @classmethod
    def of(cls, entity: str, poses: Mapping[str, Pose], place, pick_only: bool) -> FailedMove:
        """``entity`` (at ``poses[entity]``) failed to move to the point ``place`` (its
        centre there), or to be picked at all (``pick_only``)."""
        pick = Site.at(poses[entity].xyz, poses, entity)
        place = None if pick_only else Site.at(place, poses, entity)
        return cls(entity, pick, place, max(float(p.xyz[2]) for p in poses.values()))

    def columns(self, entities: Sequence[str], now: Mapping[str, Pose], places) -> list[int]:
        """The action columns this failure rules out in a state whose blocks stand at ``now``,
        its targets' points ``places`` (Y, 3): none unless the block is picked where it
        failed, with the highest stack as high or higher."""
        at = now.get(self.entity)
        if at is None or not self.pick.matches(at.xyz, now, self.entity):
            return []
        if max(float(p.xyz[2]) for p in now.values()) < self.top - SAME:
            return []  # the hand hovers lower now
        if self.place is None:
            return list(range(len(places)))
        e = entities.index(self.entity)
        return [
            j
            for j, point in enumerate(places)
            if j != e and self.place.matches(point, now, self.entity)
        ]


def failed_key(move) -> tuple[str, object]:
    """``(entity, target)`` of a move for `ArmCosts`' ``avoid``: a block name, "table", or
    ("at", place, x, y) for a move onto a planned table place (`tamp.scene.PlacedMove`: the
    place's name and the position the block was to go to, to the mm)."""
    if isinstance(move, PlacedMove) and move.at is not None:
        at = move.at
        return move.entity, ("at", move.place, round(at[0], 3), round(at[1], 3))
    return move.entity, move.target


def _column(problem: Problem, key, at, reach: float) -> int | None:
    """The action column of a `failed_key` target in ``problem`` (None when the problem has no
    such target). A place matches by name (any place when the key names none) and by
    position: the failed position lies within the place's ``reach`` (each offset is at most
    ``reach`` in x and y) of its centre, to the key's mm; the nearest such place."""
    if isinstance(key, str) and key != TABLE:
        return problem.entities.index(key)
    if at is None:  # the one table column
        return problem.n
    if isinstance(key, str):
        return None  # "somewhere on the table": no one place to blame
    _, place, x, y = key
    tol = reach * math.sqrt(2) + 1e-3
    near = [
        (math.dist(at[k], (x, y)), j)
        for j, k in enumerate(problem.fixed)
        if place in (None, k) and math.dist(at[k], (x, y)) <= tol
    ]
    return problem.n + min(near)[1] if near else None


def obstacle_tensors(scene: SceneConfig) -> tuple[torch.Tensor, torch.Tensor]:
    """The scene's obstacles as axis-aligned boxes (centres (O, 3), half extents (O, 3)) for
    the collision proxy; a turned box is replaced by its axis-aligned bounding box."""
    centres, half = [], []
    for o in scene.obstacles:
        c, s = abs(math.cos(o.yaw)), abs(math.sin(o.yaw))
        centres.append(o.centre)
        half.append((c * o.half[0] + s * o.half[1], s * o.half[0] + c * o.half[1], o.half[2]))
    as_boxes = torch.tensor(centres + half, dtype=torch.float64).reshape(2, len(centres), 3)
    return as_boxes[0], as_boxes[1]
