"""The arm's cost of every candidate move, for motion-aware task planning (`task.costs`).

`ArmCosts` is a `task.costs.CostSource` for Blocksworld problems laid out on a table scene. For
a window starting in a crisp state it predicts where every block stands (blocks keep their
observed places; a tower moved to the table stands on a free slot, `tamp.arm.predict`), then
prices each move x -> y with `motion.cost.move_costs`: the joint-space distance between the
grasp configuration at x and the release configuration on y (through pytorch-kinematics, with
gradients to the targets), plus the reach residual, an infeasibility penalty and the sphere
model's clearance to the scene's obstacles along the move and to the other blocks (boxes at
their predicted places) at its grasp and release. A place onto a tower that its slot's clearance
cannot take (`tamp.scene.SceneConfig.capacity`: a shelf over it), a move to a full table and a
grasp or release reaching `DEEP` into another block get ``blocked`` on top, and so does a move
the arm failed in that state before (``avoid``, `tamp.arm.failures.failed_key`) or, in any
state, where it failed (``failed``, `tamp.arm.failures.FailedMove`: picked and put among the
same blocks). Each point's IK is solved once per source (`tamp.arm.sites`). With ``grasps`` (the
executor's geometric fallback, `tamp.loop.geo_fallback`: tilted and side grasps, corridor
transits) the prices agree with what that executor can do: a pick or place out of top-down reach
that one of those grasps reaches, and a top-down grasp or release into a neighbour, cost
`DETOUR` instead. The matrix is computed once per state: the table placement is the scene's free
slot, or with table places (`tamp.slots`) each place's centre. With ``reach`` > 0 the places
move (continuous placements): every window optimises fresh offsets, one set per restart row,
with the logits, and the source records, for each committed move, the position the chosen row
decided it with (`ArmCosts.decided`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence

import numpy as np
import torch

from motion.cost import Blocks, Bodies, MoveCostConfig, block_depths, move_costs_batch
from motion.pick_place import PickPlaceConfig
from tamp.arm.arm import Arm
from tamp.arm.failures import column
from tamp.arm.predict import predict_poses
from tamp.arm.sites import SiteSolutions
from tamp.scene import XY, Pose, SceneConfig, free_slot, plain_move
from task.costs import IMPOSSIBLE, CostSourceBase
from task.domains.base import State
from task.problem import TABLE, Problem

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
        self.places = places  # per problem: table place -> (x, y), for slotted problems
        self.avoid = arm.avoid or {}  # plain state -> `failed_key`s of moves that failed there
        self.solver, self.q_now = arm.solver, np.asarray(arm.q_now, float)
        self.sites = SiteSolutions(self.solver, self.q_now)  # each point's IK, solved once
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
        solved = self.sites.solve(picks, places)
        extra = extra + self._deep(solved, blocks) + self._detour(solved, other, picks.shape[1])
        return _Placed(self, indices, restarts, inputs, solved, extra)

    def _price(self, todo: list[tuple[int, State]]) -> list[torch.Tensor]:
        """(N, Y) cost matrices of the (problem index, state) pairs, one batched IK call."""
        picks, places, extra, blocks, other = self._inputs(todo)
        solved = self.sites.solve(picks, places)
        with torch.no_grad():
            bodies = Bodies(self.boxes, blocks)
            c = move_costs_batch(
                self.solver, self.q_now, picks, places, self.config, bodies, solved
            )
        extra = extra + self._deep(solved, blocks) + self._detour(solved, other, picks.shape[1])
        return list(c + extra)  # (P, N, Y) each

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
                j = column(problem, key, at, self.reach)
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
        ok = self.sites.solve(points[None, :n], points[None, n:])[1]
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
