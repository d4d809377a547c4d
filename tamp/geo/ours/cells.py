"""Region cells as continuous variables of the planner's Adam, one set per restart row.

The packer (`tamp.geo.ours.pack`) places the goal regions' cells before planning; here they
stay free to move while the planner decides which object goes into which cell. For a window
whose start state leaves some cells empty, `CellWindow` gives the planner (`task.costs`) one
cost matrix per restart row: in row b, empty cell k sits at its packed centre plus
``reach * tanh(u[b, k])`` (x and y, u starting at 0 in every window), and the price of moving
object x into it is the arm's price at the packed centre (`GeoCosts.price`) plus

    carry * (|p_x - c_k(u)| - |p_x - c_k(0)|)                  (the carry, m, to the cell)
  + crowd * overlap_k(u) / area_k                              (room lost, as a share of it)

where ``p_x`` is x's position in the window's start state, ``overlap_k`` the packer's smooth
overlap area (`tamp.geo.ours.pack.overlap_loss`, ordered: of each pair the lesser direction)
of the cell's grown footprint (its hand's room) with the other cells of its region (each at
its own row's place) and the objects standing in the region, plus how far the footprint
leaves the room it may use, and ``area_k`` the cell's footprint area. A row's costs depend on
that row's u only, so each restart row optimises its own placements with its logits; the
row whose moves the planner commits gives their cells' places (`CellWindow.commit`), which
are then fixed: `Cells.settle` keeps a moved cell only when the region's packing stays free
(the packer's exact test, `tamp.geo.ours.pack._depths`, and a placing order) and every cell
inside the room it had, else the cell keeps its packed place.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import torch

from tamp.geo.ours.bridge import Bridged, own_footprint
from tamp.geo.ours.pack import PackConfig, placing_order, soft_area
from tamp.geo.places import PACK_MARGIN
from task.costs import IMPOSSIBLE
from task.domains.base import State

# m, the clearance beyond its grown footprint a moved cell keeps to every other (unless it had
# less before it moved): what a tight packing leaves is not given away
SLACK = 0.005
NEAR = 0.1  # m, obstacles this near a region's room count as its occupants (the hand's reach)


@dataclass(frozen=True)
class CellConfig:
    """How far cells move and what moving them costs."""

    reach: float = 0.015  # m, the most a cell moves from its packed centre (per axis)
    carry: float = 2.0  # rad of joint travel per m of carry (the price's joint-distance scale)
    crowd: float = 5.0  # price of a cell's hand room lost, per share of its footprint area
    lr: float = 0.3  # Adam learning rate of the unbounded u
    beta: float = 2000.0  # 1/m, softplus sharpness of the overlap (the packer's late value)


@dataclass(frozen=True)
class _Region:
    """One region's cells: names, grown and body half extents (C, 2) each, the room each
    centre may use ((C, 2) lo and hi), and the packer's settings."""

    name: str
    cells: tuple[str, ...]
    grown: np.ndarray
    body: np.ndarray
    lo: np.ndarray
    hi: np.ndarray


def _shapes(bridged: Bridged, pack: PackConfig) -> list[_Region]:
    """Each packed region's cells with their footprints (turned as the packer turned them,
    grown by the hand's room along and across each closing axis) and their room: inside the
    region's inner rectangle, by ``PACK_MARGIN`` or as far inside as the packer put them."""
    out = []
    cell_of = dict(bridged.cells)
    for region, result in bridged.packs:
        if not result.ok:
            continue
        r = bridged.scene.region(region)
        names = tuple(f"{region}.c{i}" for i in range(len(result.positions)))
        movers = [x for x, c in cell_of.items() if c in names]
        if len(movers) != len(names):
            continue
        half = np.array([own_footprint(bridged.scene.object(x)) for x in movers])
        turned = np.isclose(np.abs(np.sin(result.yaws)), 1.0)
        body = np.where(turned[:, None], half[:, ::-1], half)
        along = np.eye(2, dtype=bool)[np.asarray(result.axes, dtype=int)]
        grown = np.where(along, np.maximum(body, pack.fingers), np.maximum(body, pack.side))
        edge = grown if r.wall_height > 0 else body  # walls: the hand stays inside too
        (x0, y0), (x1, y1) = r.inner()
        xy = np.array([bridged.site(n).xy for n in names])
        inset = np.minimum(
            PACK_MARGIN, np.minimum(xy - edge - (x0, y0), (x1, y1) - xy - edge).min(-1)
        )  # (C,) how far inside the packer put each footprint, at most the margin
        inset = np.maximum(inset, 0.0)[:, None]
        lo, hi = np.array([x0, y0]) + edge + inset, np.array([x1, y1]) - edge - inset
        out.append(_Region(region, names, grown, body, lo, hi))
    return out


def hand_reaches(region: _Region, xy: np.ndarray, pack: PackConfig) -> np.ndarray:
    """(C, C) bool: with ``region``'s cells at ``xy`` (C, 2), whether cell i's hand room (its
    grown footprint) reaches cell j's body, as `tamp.geo.ours.pack.placing_order` tests it:
    where it does, j filled first leaves i no room."""
    d = np.abs(xy[:, None] - xy[None])  # (C, C, 2)
    hits = (region.grown[:, None] + region.body[None] + pack.gap - d).min(-1) > pack.tol
    np.fill_diagonal(hits, False)
    return hits


def shapes(bridged: Bridged, pack: PackConfig) -> dict[str, _Region]:
    """Each packed region's cells and footprints by region name (`_shapes`)."""
    return {r.name: r for r in _shapes(bridged, pack)}


class Cells:
    """The goal regions' cells of one bridged problem as planner variables (module docstring):
    which are empty in a state, their places now, and the places the committed rows gave."""

    def __init__(self, bridged: Bridged, pack: PackConfig, config: CellConfig = CellConfig()):
        self.config, self.pack = config, pack
        self.regions = _shapes(bridged, pack)
        self.moved: dict[str, tuple[float, float]] = {}  # cell -> the place it was settled at
        self.kept = 0  # committed places refused by the exact test

    def empty(self, state: State) -> list[tuple[_Region, list[int]]]:
        """Per region, the indices of its cells nothing stands on in ``state`` and that no
        committed move has fixed yet."""
        taken = set(state)
        out = []
        for r in self.regions:
            free = [i for i, c in enumerate(r.cells) if c not in taken and c not in self.moved]
            if free:
                out.append((r, free))
        return out

    def settle(self, bridged: Bridged, cell: str, xy) -> Bridged:
        """``bridged`` with ``cell`` at ``xy`` (brought into its room) when its region's
        packing stays free and roomy (module docstring), else as it is; the cell is fixed
        either way."""
        region = next(r for r in self.regions if cell in r.cells)
        k = region.cells.index(cell)
        now = np.array([bridged.site(c).xy for c in region.cells])
        new = now.copy()
        new[k] = np.clip(xy, region.lo[k], region.hi[k])  # onto its room (Adam may overshoot)
        fixed_xy, fixed_half = _occupants(bridged, region)
        grown, body, pack = region.grown, region.body, self.pack
        # every cell keeps the room it had (its tightest clearance, as the packer counts it)
        # or `SLACK`: the hand's room the packer grew footprints by is a proxy of what the
        # arm's check needs, and a tight packing's slack is part of that proxy
        roomy = all(
            _tightest(new, j, grown, body, fixed_xy, fixed_half, pack)
            <= max(_tightest(now, j, grown, body, fixed_xy, fixed_half, pack), -SLACK) + 1e-9
            for j in range(len(new))
        )
        order = placing_order(new, grown, body, pack.gap, pack.tol)
        ok = roomy and len(order) == len(new)
        if np.allclose(new[k], now[k]):
            self.moved[cell] = tuple(float(v) for v in now[k])
            return bridged
        self.moved[cell] = tuple(float(v) for v in (new[k] if ok else now[k]))
        if not ok:
            self.kept += 1
            return bridged
        sites = tuple(
            replace(s, xy=self.moved[cell]) if s.name == cell else s for s in bridged.sites
        )
        return replace(bridged, sites=sites)


def _tightest(xy, k: int, grown, body, fixed_xy, fixed_half, pack: PackConfig) -> float:
    """The deepest exact interpenetration (m; negative: the clearance) of cell k at ``xy[k]``
    with the other cells at ``xy`` (its grown footprint against their bodies and theirs
    against its body: whichever is placed first, the other's hand needs the room) and the
    fixed occupants."""
    d = np.abs(xy - xy[k])  # (C, 2)
    mine = (grown[k] + body + pack.gap - d).min(-1)  # (C,) my hand on their bodies
    theirs = (grown + body[k] + pack.gap - d).min(-1)  # (C,) their hands on my body
    pair = np.maximum(mine, theirs)  # both ways: a pair free either way stays free either way
    pair[k] = -math.inf
    worst = float(pair.max()) if len(pair) > 1 else -math.inf
    if len(fixed_xy):
        fixed = (grown[k] + fixed_half + pack.gap - np.abs(fixed_xy - xy[k])).min(-1)
        worst = max(worst, float(fixed.max()))
    return worst


def _occupants(bridged: Bridged, region: _Region):
    """Centres (F, 2) and half extents (F, 2) of what a cell of ``region`` keeps its room
    from besides the other cells: the objects standing in it at the start on a place that is
    not one of its cells (what the packer packed around), and the obstacles (posts, boxes)
    whose footprints come within `NEAR` of it (the packer did not see those; a cell moved
    towards a post would leave the hand less room), each as its axis-aligned bounding box."""
    from tamp.geo.ours.bridge import footprint

    start = dict(zip(bridged.problem.entities, bridged.problem.init, strict=True))
    objects = [
        bridged.scene.object(x)
        for x, s in start.items()
        if s in bridged.problem.fixed
        and s not in region.cells
        and bridged.site(s).target == region.name
    ]
    xy = [o.pose.xyz[:2] for o in objects]
    half = [footprint(o) for o in objects]
    lo, hi = region.lo.min(0) - NEAR, region.hi.max(0) + NEAR
    for o in bridged.scene.obstacles:
        c, s = abs(math.cos(o.yaw)), abs(math.sin(o.yaw))
        h = (c * o.half[0] + s * o.half[1], s * o.half[0] + c * o.half[1])
        centre = np.asarray(o.centre[:2])
        if (centre + h >= lo).all() and (centre - h <= hi).all():
            xy.append(tuple(centre))
            half.append(h)
    return (
        np.array(xy, dtype=np.float64).reshape(-1, 2),
        np.array(half, dtype=np.float64).reshape(-1, 2),
    )


@dataclass(frozen=True)
class _Term:
    """One problem's region with empty cells in a window: the problem's index, the region,
    its empty cells' indices and cost columns, every cell's place now (C, 2), the fixed
    occupants (centres, half extents), the objects' positions (N, 2) and the first of its
    cells' entries in ``u``."""

    problem: int
    region: _Region
    free: list[int]
    columns: list[int]
    xy: torch.Tensor
    fixed: tuple[torch.Tensor, torch.Tensor]
    picks: torch.Tensor
    first: int


class CellWindow:
    """The costs of one window with empty cells (`task.costs.WindowCosts`, module docstring):
    (P * R, N, Y), one matrix per restart row."""

    def __init__(self, owner, matrices: torch.Tensor, states: Sequence[State], restarts: int):
        self.owner, self.restarts = owner, restarts
        cells: Cells = owner.cells
        bridged: Bridged = owner.bridged
        self.lr = cells.config.lr
        p, r = matrices.shape[0], restarts
        self.base = matrices.repeat_interleave(r, dim=0)  # (B, N, Y)
        problem = bridged.problem
        self.terms = []  # per (problem, region): what its cells' costs need, as tensors
        count = 0
        for i, state in enumerate(states):
            world = bridged.predict(state)
            picks = torch.tensor(
                [world.object(x).pose.xyz[:2] for x in problem.entities], dtype=torch.float64
            )  # (N, 2)
            for region, free in cells.empty(state):
                xy = torch.tensor([bridged.site(c).xy for c in region.cells], dtype=torch.float64)
                fixed = tuple(torch.from_numpy(a) for a in _occupants(bridged, region))
                columns = [problem.index(region.cells[k]) for k in free]
                self.terms.append(
                    _Term(
                        problem=i,
                        region=region,
                        free=free,
                        columns=columns,
                        xy=xy,
                        fixed=fixed,
                        picks=picks,
                        first=count,
                    )
                )
                count += len(free)
        self.u = torch.zeros(p * r, max(count, 1), 2, dtype=torch.float64, requires_grad=True)

    def shifts(self) -> torch.Tensor:
        """(B, K, 2) m: every row's offset of every empty cell from its place now."""
        return self.owner.cells.config.reach * torch.tanh(self.u)

    def compute(self) -> torch.Tensor:
        config: CellConfig = self.owner.cells.config
        pack: PackConfig = self.owner.cells.pack
        out = self.base.clone()
        shift = self.shifts()
        r = self.restarts
        for t in self.terms:
            rows = slice(t.problem * r, (t.problem + 1) * r)
            centres = t.xy.expand(r, -1, -1).clone()  # (R, C, 2)
            centres[:, t.free] = centres[:, t.free] + shift[rows, t.first : t.first + len(t.free)]
            grown = torch.from_numpy(t.region.grown).expand(r, -1, -1)
            body = torch.from_numpy(t.region.body).expand(r, -1, -1)
            crowd = _per_cell_overlap(centres, grown, body, *t.fixed, pack, config)
            lo, hi = torch.from_numpy(t.region.lo), torch.from_numpy(t.region.hi)
            out_of_room = (torch.relu(lo - centres) + torch.relu(centres - hi)).sum(-1)  # (R, C)
            side = torch.from_numpy(2 * t.region.body.sum(-1))  # (C,) the footprint's width sums
            area = torch.from_numpy(4 * t.region.body.prod(-1))  # (C,)
            lost = config.crowd * (crowd + out_of_room * side) / area  # (R, C)
            for k, col in zip(t.free, t.columns, strict=True):
                carry = (t.picks - centres[:, k, None]).norm(dim=-1) - (t.picks - t.xy[k]).norm(
                    dim=-1
                )  # (R, N)
                priced = self.base[rows, :, col] < IMPOSSIBLE  # (R, N) only moves still open
                extra = config.carry * carry + lost[:, k, None]  # (R, N)
                out[rows, :, col] = torch.where(
                    priced, self.base[rows, :, col] + extra, out[rows, :, col]
                )
        return out

    def parameters(self) -> list[torch.Tensor]:
        return [self.u] if self.terms else []

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        """Fix the cells ``moves[p]`` go into at the places restart row ``rows[p]`` gave them
        (`Cells.settle`); a move planned without these costs (row None) fixes its cell where
        it is."""
        shift = self.shifts().detach()
        for t in self.terms:
            row = rows[t.problem]
            for move in moves[t.problem]:
                if move.target not in t.region.cells:
                    continue
                k = t.region.cells.index(move.target)
                if k not in t.free:
                    continue
                offset = torch.zeros(2, dtype=torch.float64)
                if row is not None:
                    offset = shift[t.problem * self.restarts + row, t.first + t.free.index(k)]
                self.owner.settle(move.target, (t.xy[k] + offset).numpy())


def _per_cell_overlap(centres, grown, body, fixed_xy, fixed_half, pack: PackConfig, config):
    """(R, C) each cell's smooth overlap area (`tamp.geo.ours.pack.overlap_loss`'s terms, per
    cell): its grown footprint against the other cells' bodies (ordered: of each pair the
    lesser direction, counted for both cells) and against the fixed occupants."""
    c = centres.shape[1]
    d = centres[:, :, None] - centres[:, None]  # (R, C, C, 2)
    pair = soft_area(d, grown[:, :, None] + body[:, None] + pack.gap, config.beta, pack.eps)
    if pack.ordered:
        pair = torch.minimum(pair, pair.transpose(1, 2))
    off = ~torch.eye(c, dtype=torch.bool)
    per = torch.where(off, pair, 0.0).sum(-1)  # (R, C)
    if fixed_xy.shape[0]:
        reach = grown[:, :, None] + fixed_half + pack.gap  # (R, C, F, 2)
        per = per + soft_area(centres[:, :, None] - fixed_xy, reach, config.beta, pack.eps).sum(-1)
    return per


__all__ = ["CellConfig", "CellWindow", "Cells"]
