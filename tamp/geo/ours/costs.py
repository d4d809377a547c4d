"""The arm's price of every candidate move of a bridged scene, for the planner (`task.costs`).

`GeoCosts` is a `task.costs.CostSource` for a `tamp.geo.ours.bridge.Bridged` problem. For a window
starting in a crisp state it predicts the world (`Bridged.predict`: objects keep their observed
poses unless moved; on a place: at its position; on an object: centred on its top), then
prices each legal move x -> y of that state:

- `task.costs.IMPOSSIBLE` when the goal rules it out (`Bridged.banned`), when x does not fit
  where it would go (the place overlaps something, `tamp.geo.places.free`; a top too small to
  stand on, `tamp.geo.places.supported_on`), when no grasp of x is free both at the pick and at
  the place, or when the top-down grasp or release has no IK solution;
- else the joint distance (rad) between the top-down grasp and release configurations, as
  `tamp.arm.costs` prices Blocksworld moves (`motion.cost`'s c(x, y) without its sphere terms),
  plus, for a move into a goal region's cell, `GeoCostConfig.order` per cell of that region
  still empty whose hand room reaches this cell's body (filling this one first closes it: the
  packer's placing-order test, `tamp.geo.ours.cells.hand_reaches`).

A grasp is free at a pose when the hand (`motion.grasps.HAND_BOXES`, the palm and both fingers,
each finger swept from open to closed on the object, as oriented boxes; `hand_shape`,
`hand_obbs`) at that grasp overlaps no other object, obstacle, region wall or floor (the
separating axis test of oriented boxes, `obb_overlap`; an upright solid as its turned box, a
cylinder as its bounding square): the geometric half of `tamp.geo.check.quick_check`,
without IK, for every grasp family at once. It is a proxy: the planner's moves are bound to a
grasp by the full check (`tamp.geo.ours.planner`), and what fails there comes back as failure
memory: `avoid(state, move, grasp, place)` rules the move out only under the grasp (None:
every grasp) and place that failed, so the same move keeps its price while another of its
grasps is left, and x -> another place is priced on its own, unless the grasp failed on the
pick side (reaching or closing on x, whatever the place): then it is out for x's moves to every
place in that state. A failure no movable object took
part in (no IK solution, a post, the table or a wall hit; ``fixed``) holds in every state where
the object stands where it stood, so later plans do not try that grasp again from another
order of the other moves.

With empty region cells (`tamp.geo.ours.cells`) a window's costs are one matrix per restart
row, the cells' places optimised with the logits, and the row whose moves are committed fixes
them (`GeoCosts.settle`; a moved cell forgets the prices seen so far).

Every state is priced once (cached); the IK solutions are cached by target position (to the
mm) across states, so later windows solve only the targets they have not seen. Binding a plan
asks for one move in each state it passes (`GeoCosts.price_of`, `GeoCosts.grasps_left`): that
move alone is priced there, as the whole state's pricing would price it, unless the state was
priced whole already. ``stats`` records states priced, single moves priced and the time spent
(ms per state).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import torch

from motion.grasps import HAND_BOXES, Grasp
from motion.ik import IKSolver, top_down_pose
from tamp.geo.ours.bridge import PACK, Bridged
from tamp.geo.ours.cells import CellConfig, Cells, CellWindow, hand_reaches, shapes
from tamp.geo.ours.pack import PackConfig
from tamp.geo.places import free, supported_on
from tamp.world.geometry import Solid, fixed_solids, of_movable
from tamp.world.schema import Scene
from task.costs import IMPOSSIBLE, CostSourceBase
from task.domains.base import State
from task.domains.blocksworld import check_move as legal
from task.problem import Move

TOUCH = 0.001  # m, boxes may touch this deep (contact)


@dataclass(frozen=True)
class GeoCostConfig:
    """Weights of the move price."""

    joint_weight: float = 1.0  # per rad of joint distance, grasp -> release configuration
    choices: tuple[str, ...] = ("top", "side", "tilt")  # grasp families priced
    ik: bool = True  # rule out a grasp or release with no top-down IK solution (needs a solver)
    margin: float = 0.004  # m, the open hand's boxes grown by this (the collision margin)
    # added per empty cell of its region a move into a cell closes: one whose hand room (the
    # packer's grown footprint) reaches this cell's body, so it must be filled first
    # (`tamp.geo.ours.pack.placing_order`'s test); a detour's price, not a rule: the arm's
    # other grasps may still fit there
    order: float = 1.0
    # the goal regions' empty cells as variables of the planner's Adam, per restart row
    # (`tamp.geo.ours.cells`); None: they stay where the packer put them
    cells: CellConfig | None = field(default_factory=CellConfig)


def hand_shape(grasp: Grasp) -> tuple:
    """The open hand's boxes (centre, half extents) in the TCP frame at ``grasp``
    (`motion.grasps.HAND_BOXES`), each finger swept in to where it closes on the object (the
    object's width apart): the room the fingers take while they open, close, carry and let go."""
    (palm, *fingers) = HAND_BOXES
    out = [palm]
    for (cx, cy, cz), (hx, hy, hz) in fingers:
        outer = abs(cy) + hy
        inner = min(abs(cy) - hy, grasp.width / 2)
        side = 1.0 if cy > 0 else -1.0
        out.append(((cx, side * (outer + inner) / 2, cz), (hx, (outer - inner) / 2, hz)))
    return tuple(out)


def hand_obbs(grasps: Sequence[Grasp], margin: float = 0.0):
    """The hand's palm and finger boxes (`hand_shape`, grown by ``margin``) at each grasp as
    oriented boxes in the frame of the object held: centres (G, 3, 3), axes (G, 3, 3, 3) (each
    box's rotation: its axes as columns), half extents (G, 3, 3), m."""
    g = len(grasps)
    centres, axes, halves = np.zeros((g, 3, 3)), np.zeros((g, 3, 3, 3)), np.zeros((g, 3, 3))
    for i, grasp in enumerate(grasps):
        m = grasp.matrix  # (4, 4) TCP in the object frame
        for k, (centre, half) in enumerate(hand_shape(grasp)):
            centres[i, k] = m[:3, :3] @ np.asarray(centre) + m[:3, 3]
            axes[i, k] = m[:3, :3]
            halves[i, k] = np.asarray(half) + margin
    return centres, axes, halves


def solid_obbs(solids: Sequence[Solid]):
    """Upright solids as oriented boxes: centres (S, 3), axes (S, 3, 3), half extents (S, 3);
    a cylinder as its bounding square."""
    centres = np.array([s.centre for s in solids], dtype=np.float64).reshape(-1, 3)
    halves = np.array([s.half for s in solids], dtype=np.float64).reshape(-1, 3)
    yaws = np.array([0.0 if s.cylinder else s.yaw for s in solids], dtype=np.float64)
    return centres, _turn(yaws), halves


def hand_in_world(hand, xyz, yaw: float):
    """``hand`` (`hand_obbs` of G grasps, in the held object's frame) with the object centred
    at ``xyz`` (m) turned ``yaw`` (rad): the 3 G boxes in the world, flat, as `obb_overlap`
    takes them."""
    centres, axes, halves = hand
    turn = _turn(np.asarray(yaw))  # (3, 3)
    return (
        (centres @ turn.T + np.asarray(xyz)).reshape(-1, 3),
        (turn @ axes).reshape(-1, 3, 3),
        halves.reshape(-1, 3),
    )


def _turn(yaws: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations about z by ``yaws`` (...,)."""
    c, s = np.cos(yaws), np.sin(yaws)
    out = np.zeros((*np.shape(yaws), 3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = 1.0
    return out


def obb_overlap(a, b, touch: float = TOUCH) -> np.ndarray:
    """(A, B) True where oriented box a_i and b_j interpenetrate more than ``touch`` (m) on
    every one of the 15 separating axes (the separating axis theorem: two convex boxes are
    apart when their projections on some face normal or edge cross product are); pairs whose
    axis-aligned bounds are apart are not tested further. ``a``, ``b``: (centres (N, 3), axes
    (N, 3, 3), half extents (N, 3)) as `hand_obbs` and `solid_obbs`."""
    (ca, ra, ha), (cb, rb, hb) = a, b
    bound_a = np.einsum("aij,aj->ai", np.abs(ra), ha)  # (A, 3) axis-aligned half extents
    bound_b = np.einsum("bij,bj->bi", np.abs(rb), hb)  # (B, 3)
    near = (np.abs(cb[None] - ca[:, None]) < bound_a[:, None] + bound_b[None] - touch).all(-1)
    out = np.zeros((len(ca), len(cb)), dtype=bool)
    ia, ib = np.nonzero(near)  # (K,) the pairs left
    if not len(ia):
        return out
    ua, ub = np.swapaxes(ra[ia], -1, -2), np.swapaxes(rb[ib], -1, -2)  # (K, 3 axes, 3)
    cross = np.cross(ua[:, :, None, :], ub[:, None, :, :]).reshape(-1, 9, 3)
    axes = np.concatenate([ua, ub, cross], axis=1)  # (K, 15, 3)
    reach_a = (np.abs(np.einsum("kld,kid->kli", axes, ua)) * ha[ia][:, None]).sum(-1)
    reach_b = (np.abs(np.einsum("kld,kid->kli", axes, ub)) * hb[ib][:, None]).sum(-1)
    gap = np.abs(np.einsum("kld,kd->kl", axes, cb[ib] - ca[ia]))  # (K, 15)
    length = np.linalg.norm(axes, axis=-1)  # 0 for parallel edges: never separating
    out[ia, ib] = ~(gap > reach_a + reach_b - touch * length).any(-1)
    return out


def _stands(world: Scene, x: str) -> tuple[int, ...]:
    """Where object ``x`` stands in ``world``: its centre (mm) and yaw (mrad)."""
    pose = world.object(x).pose
    return (*(round(float(v) * 1000) for v in pose.xyz), round(float(pose.yaw) * 1000))


@dataclass
class _Seen:
    """A state's predicted world, its fixed solids and each object's body as oriented boxes
    (`solid_obbs`), and what pricing found there: each object's grasps free where it stands
    (``picks``) and the solids its hand must clear (``solids``: all but the object)."""

    world: Scene
    fixed: tuple
    bodies: dict
    picks: dict = field(default_factory=dict)
    solids: dict = field(default_factory=dict)


class _Window:
    """The costs of one window: a fixed (P, N, Y) matrix, alike for every restart row."""

    lr = 0.0

    def __init__(self, matrix: torch.Tensor) -> None:
        self.matrix = matrix

    def compute(self) -> torch.Tensor:
        return self.matrix  # (P, N, Y)

    def parameters(self) -> list[torch.Tensor]:
        return []

    def commit(self, rows, moves) -> None:
        """Nothing to record: no cell of this window is empty (or cells are off)."""


class GeoCosts(CostSourceBase):
    """`task.costs.CostSource` of one bridged problem (module docstring). ``solver`` and ``q``
    (J,): the IK solver and the arm configuration it is seeded from (None: no IK, the price is
    geometry only and the joint distance 0)."""

    can_forget = True  # the fallback may start a plan over: nothing here goes stale (`forget`)

    def __init__(
        self,
        bridged: Bridged,
        solver: IKSolver | None = None,
        q=None,
        config: GeoCostConfig = GeoCostConfig(),
        grasps=None,
        pack: PackConfig = PACK,
    ) -> None:
        self.bridged, self.solver, self.config = bridged, solver, config
        # the empty cells the planner's Adam moves (`pack`: the packer's settings they keep)
        self.cells = None if config.cells is None else Cells(bridged, pack, config.cells)
        self._pack = pack
        self._shapes = shapes(bridged, pack)  # the goal regions' cell footprints (`_closes`)
        self.q = None if q is None else np.asarray(q, dtype=np.float64)
        if grasps is None:
            from tamp.geo.check import candidate_grasps

            grasps = {o.name: candidate_grasps(o, config.choices) for o in bridged.scene.objects}
        self.grasps: dict[str, tuple[Grasp, ...]] = dict(grasps)
        self._base: dict[State, tuple[np.ndarray, dict]] = {}
        # moves priced one at a time (`price_of`): (state, move) -> (price, grasp names)
        self._single: dict[tuple[State, Move], tuple[float, tuple[str, ...]]] = {}
        self._seen: dict[State, _Seen] = {}  # the predicted world of a state, its solids
        self._ik: dict[tuple[int, int, int], tuple[np.ndarray, bool]] = {}
        self._hands: dict[str, tuple] = {}  # object -> `hand_obbs` of its grasps
        self.failed: dict[tuple[State, Move, str], set] = {}
        # failures no movable object caused (IK, a post, the table, a wall): (move, where the
        # object stands, place) -> grasps, whatever the other objects do
        self.failed_fixed: dict[tuple[Move, tuple, str], set] = {}
        # grasps that failed on the pick side (reaching or closing on the object, whatever the
        # place): (state, object) -> grasps, for the object's moves to every place there
        self.failed_pick: dict[tuple[State, str], set] = {}
        self.stats = {"states": 0, "moves": 0, "price_s": 0.0, "ik_targets": 0}

    # ---- the planner's interface

    def __call__(self, indices: Sequence[int], states: Sequence[State], restarts: int = 1):
        """The costs of a window (`task.costs.CostSource`): (P, N, Y), one row per problem, or
        with empty cells (`tamp.geo.ours.cells`) one per restart row, their places optimised
        with the logits."""
        rows = torch.stack([torch.from_numpy(self.price(s)) for s in states])
        if self.cells is not None and any(self.cells.empty(s) for s in states):
            return CellWindow(self, rows, states, restarts)
        return _Window(rows)

    def forget(self, index: int) -> None:
        """Nothing to drop when the planner's fallback starts its plan over from the initial
        state (`task.planner`): the moves the windows committed left nothing here but the
        cells they settled, and a settled cell keeps the region's packing free, so a plan from
        the initial state is priced and bound with the cells where they are now."""

    def settle(self, cell: str, xy) -> None:
        """Fix ``cell`` at ``xy`` (m) where its region's packing stays free
        (`tamp.geo.ours.cells.Cells.settle`); the prices of the states seen so far are
        forgotten when it moved (they depend on where the cells are)."""
        settled = self.cells.settle(self.bridged, cell, xy)
        if settled is not self.bridged:
            self.bridged = settled
            self._base.clear()
            self._single.clear()
            self._seen.clear()

    def price(self, state: State) -> np.ndarray:
        """(N, Y) the price of every move x -> y in crisp ``state`` (0 where illegal)."""
        out = self._priced(state)[0].copy()
        problem = self.bridged.problem
        remembered = {move for _, move, _ in self.failed} | {m for m, _, _ in self.failed_fixed}
        for s, x in self.failed_pick:  # every move of an object whose pick failed here
            if s == tuple(state):
                remembered |= {Move(x, y) for y in problem.targets if y != x}
        world = self.bridged.predict(state) if remembered else None
        for move in remembered:
            if legal(problem, state, move) is None and not self.grasps_left(state, move, world):
                out[problem.entities.index(move.entity), problem.index(move.target)] = IMPOSSIBLE
        return out

    def price_of(self, state: State, move: Move) -> float:
        """The price of ``move`` in crisp ``state``, as `price` gives it (0 where illegal),
        the move alone priced where the state was not priced whole."""
        if tuple(state) in self._base:
            p = self.bridged.problem
            return float(self.price(state)[p.entities.index(move.entity), p.index(move.target)])
        if legal(self.bridged.problem, state, move) is not None:
            return 0.0
        price, _ = self._move(state, move)
        if price >= IMPOSSIBLE or not self._remembers(move, state):
            return price
        return price if self.grasps_left(state, move) else float(IMPOSSIBLE)

    def _remembers(self, move: Move, state: State) -> bool:
        return (
            any(m == move for _, m, _ in self.failed)
            or any(m == move for m, _, _ in self.failed_fixed)
            or (tuple(state), move.entity) in self.failed_pick
        )

    # ---- failure memory

    def avoid(
        self,
        state: State,
        move: Move,
        grasp: str | None,
        place: str,
        fixed: bool = False,
        side: str = "",
    ) -> None:
        """Rule ``move`` out in ``state`` under ``grasp`` (a name; None: every grasp) and the
        place named ``place``, where it failed. ``fixed``: what failed involved no movable
        object (no IK solution, a fixed obstacle, the table, a region's wall hit), so the
        move is ruled out under that grasp and place in every state where its object stands
        where it stands in ``state``. ``side`` "pick": the grasp failed reaching or closing on
        the object (`tamp.geo.check.GraspTry`), so it is ruled out for the object's moves to
        every place in ``state``, not only to ``place``."""
        self.failed.setdefault((tuple(state), move, place), set()).add(grasp)
        if side == "pick":
            self.failed_pick.setdefault((tuple(state), move.entity), set()).add(grasp)
        if fixed:
            key = (move, _stands(self.bridged.predict(state), move.entity), place)
            self.failed_fixed.setdefault(key, set()).add(grasp)

    def grasps_left(self, state: State, move: Move, world: Scene | None = None) -> tuple[str, ...]:
        """The names of ``move``'s grasps free at both ends in ``state`` (best first: the
        order of `tamp.geo.check.candidate_grasps`) that no failure ruled out. ``world``: the
        predicted world of ``state`` when the caller has it."""
        _, names = self._move(state, move)
        world = world or self._world(state)
        place = self.bridged.geo_move(world, move).place.name
        gone = self.failed.get((tuple(state), move, place), set())
        gone = gone | self.failed_fixed.get((move, _stands(world, move.entity), place), set())
        gone = gone | self.failed_pick.get((tuple(state), move.entity), set())
        if None in gone:
            return ()
        return tuple(n for n in names if n not in gone)

    # ---- pricing

    def _priced(self, state: State) -> tuple[np.ndarray, dict]:
        state = tuple(state)
        if state not in self._base:
            t0 = time.perf_counter()
            self._base[state] = self._price(state)
            self.stats["states"] += 1
            self.stats["price_s"] += time.perf_counter() - t0
        return self._base[state]

    def _move(self, state: State, move: Move) -> tuple[float, tuple[str, ...]]:
        """The price of one move in ``state`` (before failure memory) and the names of its
        grasps free at both ends: from the whole state's pricing where it was done, else
        that move alone, priced as `_price` prices it."""
        state = tuple(state)
        if state in self._base:
            out, allowed = self._base[state]
            p = self.bridged.problem
            return float(out[p.entities.index(move.entity), p.index(move.target)]), allowed.get(
                move, ()
            )
        key = (state, move)
        if key not in self._single:
            t0 = time.perf_counter()
            self._single[key] = self._price_move(state, move)
            self.stats["moves"] += 1
            self.stats["price_s"] += time.perf_counter() - t0
        return self._single[key]

    def _price_move(self, state: State, move: Move) -> tuple[float, tuple[str, ...]]:
        if legal(self.bridged.problem, state, move) is not None:
            return 0.0, ()
        ((names, ends),) = self._judge(state, [move])
        if not names:
            return float(IMPOSSIBLE), names
        if self.solver is None:
            return self._order(state, move.target), names
        q, reach = self._solve(list(ends))  # (2, J), (2,)
        if self.config.ik and not (reach[0] and reach[1]):
            return float(IMPOSSIBLE), names
        dist = float(np.linalg.norm(q[1] - q[0]))
        price = self.config.joint_weight * dist + self._order(state, move.target)
        return min(price, IMPOSSIBLE - 1.0), names

    def _world(self, state: State) -> Scene:
        return self._context(state).world

    def _context(self, state: State) -> _Seen:
        state = tuple(state)
        if state not in self._seen:
            world = self.bridged.predict(state)
            fixed = solid_obbs(fixed_solids(world))
            bodies = {o.name: solid_obbs([of_movable(o)]) for o in world.objects}
            self._seen[state] = _Seen(world, fixed, bodies)
        return self._seen[state]

    def _fits(self, state: State, move: Move):
        """Where a legal ``move`` puts its object in ``state``'s predicted world (a `Place`),
        or None where the goal rules the move out or the object does not fit there."""
        b, world, x = self.bridged, self._world(state), move.entity
        geo = b.geo_move(world, move)
        ok = (x, move.target) not in b.banned and free(world, x, geo.place)
        if ok and move.target in b.problem.entities:
            ok = supported_on(world.object(x), world.object(move.target), geo.place.yaw)
        return geo.place if ok else None

    def _judge(self, state: State, moves: Sequence[Move]) -> list[tuple]:
        """For each legal move of ``moves`` (of any objects) in ``state``: the names of its
        grasps free at both ends (best first: the order of
        `tamp.geo.check.candidate_grasps`; none where `_fits` finds no place), and the
        object's position and the place's (m) the arm's price is measured between. The hand
        is tested at all the places of one object at once (`_free_grasps`)."""
        seen = self._context(state)
        world = seen.world
        places = [self._fits(state, move) for move in moves]
        by_object: dict[str, list[int]] = {}
        for k, (move, place) in enumerate(zip(moves, places, strict=True)):
            if place is not None:
                by_object.setdefault(move.entity, []).append(k)
        free_at: dict[int, set[str]] = {}
        for x, ks in by_object.items():
            o = world.object(x)
            poses = [(places[k].xyz, places[k].yaw) for k in ks]
            if x in seen.picks:
                found = self._free_grasps(world, x, poses, seen)
            else:  # where x stands too
                *found, seen.picks[x] = self._free_grasps(
                    world, x, [*poses, (o.pose.xyz, o.pose.yaw)], seen
                )
            free_at.update(zip(ks, found, strict=True))
        out = []
        for k, (move, place) in enumerate(zip(moves, places, strict=True)):
            if place is None:
                out.append(((), None))
                continue
            x = move.entity
            # best first, in `candidate_grasps`' order (a set's order changes with the
            # process's string hashing, and with it which grasp binding tries first)
            ok = seen.picks[x] & free_at[k]
            names = tuple(g.name for g in self.grasps[x] if g.name in ok)
            out.append((names, (world.object(x).pose.xyz, place.xyz)))
        return out

    def _price(self, state: State) -> tuple[np.ndarray, dict]:
        problem = self.bridged.problem
        out = np.zeros((problem.n, len(problem.targets)))
        cells = [
            (i, j, Move(x, target))
            for i, x in enumerate(problem.entities)
            for j, target in enumerate(problem.targets)
            if legal(problem, state, Move(x, target)) is None
        ]
        judged = self._judge(state, [move for _, _, move in cells])
        allowed: dict[Move, tuple[str, ...]] = {}
        moves, ends = [], []
        for (i, j, move), (names, where) in zip(cells, judged, strict=True):
            allowed[move] = names
            if not names:
                out[i, j] = IMPOSSIBLE
                continue
            moves.append((i, j))
            ends.append(where)
        if moves and self.solver is not None:
            q, reach = self._solve([p for e in ends for p in e])  # (2M, J), (2M,)
            for k, (i, j) in enumerate(moves):
                if self.config.ik and not (reach[2 * k] and reach[2 * k + 1]):
                    out[i, j] = IMPOSSIBLE
                    continue
                dist = float(np.linalg.norm(q[2 * k + 1] - q[2 * k]))
                out[i, j] = min(self.config.joint_weight * dist, IMPOSSIBLE - 1.0)
        if self.config.order and self._shapes:
            closes = self._closes(state)
            for i, j in moves:
                closed = closes.get(problem.targets[j], 0)
                if closed and out[i, j] < IMPOSSIBLE:
                    out[i, j] = min(out[i, j] + self.config.order * closed, IMPOSSIBLE - 1.0)
        return out, allowed

    def closes(self, state: State) -> dict[str, int]:
        """Goal cell -> how many other empty cells of its region filling it closes in crisp
        ``state`` (`_closes`); empty without goal regions."""
        return self._closes(state) if self._shapes else {}

    def _closes(self, state: State) -> dict[str, int]:
        """Goal cell -> how many other cells of its region, empty in ``state``, filling it
        closes: their hand room reaches its body where the cells are now (`hand_reaches`)."""
        b, taken = self.bridged, set(state)
        out: dict[str, int] = {}
        for region in self._shapes.values():
            xy = np.array([b.site(c).xy for c in region.cells])
            reaches = hand_reaches(region, xy, self._pack)  # (C, C): i's hand on j's body
            empty = np.array([c not in taken for c in region.cells])
            for k, cell in enumerate(region.cells):
                others = empty.copy()
                others[k] = False
                out[cell] = int((reaches[:, k] & others).sum())
        return out

    def _order(self, state: State, target: str) -> float:
        """``config.order`` per cell a move onto ``target`` closes in ``state`` (`_closes`)."""
        if not self.config.order or not self._shapes:
            return 0.0
        return self.config.order * self._closes(state).get(target, 0)

    def _free_grasps(self, world: Scene, x: str, poses, seen: _Seen) -> list[set[str]]:
        """For each of ``poses`` ((xyz, yaw): x centred at xyz (m) turned yaw (rad)), the
        names of x's grasps whose open hand overlaps nothing but x (the other objects where
        ``world`` has them, the fixed solids: oriented boxes, `solid_obbs`, of ``seen``); all
        of x's grasps at all the poses at once (`obb_overlap`)."""
        if x not in seen.solids:
            others = [seen.bodies[o.name] for o in world.objects if o.name != x]
            seen.solids[x] = tuple(
                np.concatenate(parts) for parts in zip(seen.fixed, *others, strict=True)
            )
        solids = seen.solids[x]
        if x not in self._hands:
            self._hands[x] = hand_obbs(self.grasps[x], self.config.margin)
        count = len(self._hands[x][0])  # G grasps
        if not count or not len(solids[0]) or not poses:
            return [{g.name for g in self.grasps[x]} for _ in poses]
        hands = [hand_in_world(self._hands[x], xyz, yaw) for xyz, yaw in poses]
        hand = tuple(np.concatenate(parts) for parts in zip(*hands, strict=True))
        hit = obb_overlap(hand, solids).reshape(len(poses), count, -1).any(-1)  # (P, G)
        return [{g.name for g, h in zip(self.grasps[x], row, strict=True) if not h} for row in hit]

    def _solve(self, points: list) -> tuple[np.ndarray, np.ndarray]:
        """Top-down IK (yaw 0) of every point (m), cached to the mm: (M, J), (M,)."""
        keys = [tuple(round(float(v) * 1000) for v in p) for p in points]
        todo = sorted({k for k in keys if k not in self._ik})
        if todo:
            targets = np.stack([top_down_pose(np.asarray(k) / 1000.0, 0.0) for k in todo])
            q_ref = self.q if self.q is not None else np.zeros(self.solver.dof)
            found = self.solver.solve(targets, q_ref)
            self.stats["ik_targets"] += len(todo)
            for k, q, ok in zip(todo, found.q, found.ok, strict=True):
                self._ik[k] = (np.asarray(q), bool(ok))
        q = np.stack([self._ik[k][0] for k in keys])
        ok = np.array([self._ik[k][1] for k in keys])
        return q, ok
