"""Gradient-optimised placements in a region: where M objects go, decided jointly.

`pack` places M axis-aligned footprints (half extents ``(M, 2)``) inside a region's inner
rectangle, free of each other and of F fixed occupants (objects already there, posts), by Adam
over the centres of R restart rows at once (one tensor program, nanoGPT style); the free row
of least overlap that admits a placing order wins (else the row of least overlap). Centres
are inside by construction: the unbounded variables u map into the rectangle shrunk by each
footprint,

    x_m = lo + h_m + (hi - lo - 2 h_m) * sigmoid(u_m)                       (per axis)

and the loss of a row is the smooth overlap area of every pair of grown footprints,

    L = sum_{i<j} s(h_i + h_j + g - |x_i - x_j|_x) s(...)_y + sum_{i, f} (same, fixed f)

with s(z) = softplus(beta z) / beta (beta anneals from `PackConfig.beta` to ``beta_end``, so the
early landscape is smooth and the late one close to the exact area) and |.| smoothed as
sqrt(d^2 + eps^2). ``g`` is `PackConfig.gap`, a clearance between neighbours. Finger room for a
top grasp is `PackConfig.fingers` and ``side``: along its closing axis each object's footprint
reaches at least ``fingers`` from its centre (where the open finger pads are), across it at
least ``side`` (the fingers' and the hand's width), against the other objects' bodies and the
region's edges (its walls), and the
closing axis of each object (x or y) is drawn per restart row, as is each footprint's yaw
(0 or pi/2: a cuboid turned a quarter turn swaps its half extents). Yaws are thus chosen among
{0, pi/2} across restarts, not optimised; footprints are axis-aligned (a cylinder's is its
bounding square). The hand needs its room only when its object is placed, among the objects
placed before: with `PackConfig.ordered` (the default) a pair counts the lesser of its two
directions (whichever goes second needs the room), and the packing must admit a placing order
(`placing_order`; the planner finds its own with the arm's prices). A packing is ``ok`` when no
pair interpenetrates more than `PackConfig.tol`, every footprint lies inside and (ordered) an
order exists.

`pack_sampled` is the baseline a greedy TAMP system uses: objects in order, each at a uniform
random position inside until one is free of those placed before (its hand too; rejection
sampling), starting over from the first object when one finds no position in its share of
tries, until the budget of samples is spent.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
import torch

from motion.grasps import FINGER_SPARE, STROKE
from task.errors import TampError
from task.optimize import Adam

Rect = tuple[tuple[float, float], tuple[float, float]]  # ((x0, y0), (x1, y1)), m


class PackError(TampError):
    """Bad input to the packer (shapes, a footprint larger than the region); ``index``: the
    footprint that does not fit (None for other input), so a caller can name its object."""

    def __init__(self, message: str, index: int | None = None):
        super().__init__(message)
        self.index = index


@dataclass(frozen=True)
class PackConfig:
    """Settings of `pack` (lengths in m)."""

    restarts: int = 32  # R rows optimised together; the best wins
    steps: int = 150  # Adam steps
    lr: float = 0.3  # Adam learning rate on the unbounded u
    beta: float = 100.0  # 1/m, softplus sharpness at the first step ...
    beta_end: float = 3000.0  # ... and at the last (geometric annealing)
    eps: float = 1e-4  # m, smoothing of |d|
    gap: float = 0.002  # m, clearance kept between two footprints (and counted when checking)
    fingers: float = 0.0  # m, the hand's reach from the object's centre along the closing axis
    # (open finger pads, with the collision model's margin); 0: no finger room
    side: float = 0.0  # m, the hand's reach from the centre across the closing axis
    # m, the widest side the open fingers close across, each clearing it by `FINGER_SPARE`
    # (`motion.grasps`: no grasp of a wider side is made); a side this wide or wider is never
    # the closing axis
    stroke: float = STROKE - 2 * FINGER_SPARE
    tol: float = 1e-4  # m, interpenetration still counted as free
    ordered: bool = True  # finger room against the objects placed before only: a pair is free
    # when either's hand clears the other's body, and some placing order must exist (`order`)
    margin: float = 0.0  # m, the footprints keep this far inside the region's rectangle (a
    # placed object settles a millimetre or two from where it was released: a footprint
    # flush with a marked area's edge may be read as standing outside it)


@dataclass(frozen=True)
class PackResult:
    """The best packing: ``positions`` (M, 2) centres, ``yaws`` (M,) in {0, pi/2}, ``axes``
    (M,) each object's closing axis (0: x, 1: y, in the world frame), ``ok`` when free and
    inside, ``overlap`` the deepest interpenetration left (m), ``time`` (s), ``tries`` (Adam
    row-steps or samples spent), ``order`` an order of placing them in which each object's
    hand clears those placed before (empty when none exists)."""

    positions: np.ndarray
    yaws: np.ndarray
    axes: np.ndarray
    ok: bool
    overlap: float
    time: float
    tries: int
    order: tuple[int, ...] = ()


class Occupants(NamedTuple):
    """The fixed occupants of a region that a packing must keep clear of: centres ``xy``
    (F, 2) and half extents ``half`` (F, 2), m."""

    xy: Sequence = ()
    half: Sequence = ()


NO_OCCUPANTS = Occupants()


def _check(inner: Rect, half, fixed: Occupants) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    fixed_xy, fixed_half = fixed
    half = np.asarray(half, dtype=np.float64).reshape(-1, 2)
    fxy = np.asarray(fixed_xy if fixed_xy is not None else (), dtype=np.float64).reshape(-1, 2)
    fh = np.asarray(fixed_half if fixed_half is not None else (), dtype=np.float64).reshape(-1, 2)
    if fxy.shape != fh.shape:
        raise PackError(f"fixed centres {fxy.shape} and half extents {fh.shape} differ in shape")
    (x0, y0), (x1, y1) = inner
    room = min(x1 - x0, y1 - y0)
    if len(half) and 2 * half.min(1).max() > room:
        i = int(half.min(1).argmax())
        raise PackError(
            f"footprint {i} ({2 * half[i, 0]:g} x {2 * half[i, 1]:g} m) does not fit the "
            f"region's inner rectangle ({x1 - x0:g} x {y1 - y0:g} m) however it is turned",
            index=i,
        )
    return half, fxy, fh


def _grown(half: torch.Tensor, turn: torch.Tensor, axis: torch.Tensor, config: PackConfig):
    """(R, M, 2) half extents of each row: the bodies, turned (swapped) where ``turn``, and
    the bodies grown to the hand's reach: ``fingers`` along ``axis`` (the closing axis),
    ``side`` across it."""
    h = torch.where(turn[..., None], half.flip(-1), half)  # (R, M, 2)
    along = torch.nn.functional.one_hot(axis, 2).bool()  # (R, M, 2)
    return h, torch.where(along, h.clamp_min(config.fingers), h.clamp_min(config.side))


def soft_area(d: torch.Tensor, reach: torch.Tensor, beta: float, eps: float) -> torch.Tensor:
    """Smooth overlap area of boxes whose centres are ``d`` (..., 2) apart and whose half
    extents sum to ``reach`` (..., 2): prod over x, y of softplus(beta (reach - |d|)) / beta."""
    depth = reach - torch.sqrt(d * d + eps * eps)  # (..., 2)
    return (torch.nn.functional.softplus(beta * depth) / beta).prod(-1)


def overlap_loss(
    xy: torch.Tensor,
    half: torch.Tensor,
    body: torch.Tensor,
    fixed_xy: torch.Tensor,
    fixed_half: torch.Tensor,
    beta: float,
    config: PackConfig,
) -> torch.Tensor:
    """(R,) the packing loss of each row (module docstring) at softplus sharpness ``beta``.
    ``xy`` (R, M, 2) centres, ``half`` (R, M, 2) grown half extents (finger room), ``body``
    (R, M, 2) the bodies' own; fixed occupants ``fixed_xy`` / ``fixed_half`` (F, 2). Of
    ``config``: the smoothing ``eps``, the clearance ``gap`` and ``ordered``. A grown footprint
    must clear the other bodies: pairs count both ways (i's fingers against j's body and j's
    against i's), or with ``ordered`` the lesser of the two (whichever is placed second needs
    the room)."""
    eps, gap = config.eps, config.gap
    m = xy.shape[1]
    d = xy[:, :, None] - xy[:, None]  # (R, M, M, 2)
    reach = half[:, :, None] + body[:, None] + gap  # (R, M, M, 2): i grown, j body
    pair = soft_area(d, reach, beta, eps)  # (R, M, M)
    if config.ordered:
        pair = torch.minimum(pair, pair.transpose(1, 2))  # (R, M, M), symmetric
    off = ~torch.eye(m, dtype=torch.bool)
    loss = torch.where(off, pair, 0.0).sum((-1, -2))  # (R,)
    if fixed_xy.shape[0]:
        df = xy[:, :, None] - fixed_xy  # (R, M, F, 2)
        loss = loss + soft_area(df, half[:, :, None] + fixed_half + gap, beta, eps).sum((-1, -2))
    return loss


def _depths(xy, half, body, fxy, fh, gap: float, ordered: bool = False) -> np.ndarray:
    """(R,) the deepest exact interpenetration (m) of each row's grown footprints, with gap
    (``ordered``: of each pair, the lesser of its two directions)."""
    d = np.abs(xy[:, :, None] - xy[:, None])  # (R, M, M, 2)
    pen = (half[:, :, None] + body[:, None] + gap - d).min(-1)  # (R, M, M): i's hand, j's body
    if ordered:
        pen = np.minimum(pen, pen.transpose(0, 2, 1))
    m = xy.shape[1]
    pen[:, np.arange(m), np.arange(m)] = -np.inf
    worst = pen.reshape(len(xy), -1).max(-1) if m > 1 else np.full(len(xy), -np.inf)
    if len(fxy):
        pf = (half[:, :, None] + fh + gap - np.abs(xy[:, :, None] - fxy)).min(-1)  # (R, M, F)
        worst = np.maximum(worst, pf.reshape(len(xy), -1).max(-1))
    return worst


def placing_order(xy, half, body, gap: float, tol: float) -> tuple[int, ...]:
    """An order of placing M footprints at ``xy`` (M, 2) in which each one's hand (``half``,
    (M, 2) grown) clears the bodies (``body``) placed before it, found backwards (the last
    placed clears every other); () when there is none."""
    d = np.abs(xy[:, None] - xy[None])  # (M, M, 2)
    hits = (half[:, None] + body[None] + gap - d).min(-1) > tol  # (M, M): i's hand on j's body
    np.fill_diagonal(hits, False)
    left, backwards = list(range(len(xy))), []
    while left:
        last = next((i for i in left if not hits[i, left].any()), None)
        if last is None:
            return ()
        backwards.append(last)
        left.remove(last)
    return tuple(reversed(backwards))


def pack(
    inner: Rect,
    footprints: Sequence,
    fixed: Occupants = NO_OCCUPANTS,
    config: PackConfig = PackConfig(),
    seed: int = 0,
    turnable: Sequence[bool] | None = None,
    walled: bool = True,
) -> PackResult:
    """Place the M ``footprints`` (half extents (M, 2), m) inside ``inner`` free of each other
    and of the ``fixed`` occupants (`Occupants`); see the module docstring.
    ``turnable[m]``: whether footprint m may turn a quarter turn (default: when it is not
    square); ``walled``: the hand must stay inside the region too (walls stand on its edges;
    a marked area lets the fingers reach beyond it)."""
    (result,) = pack_tries(inner, footprints, fixed, ((config, seed),), turnable, walled)
    return result


@dataclass(frozen=True)
class _Try:
    """One packing's rows in a batch of tries: its rectangle's corner ``lo`` and ``span``, what
    must stay inside (``edge``) and the room its centres may use, each row's yaw turn and
    closing axis, grown and body half extents, and its rows' place in the batch."""

    config: PackConfig
    lo: torch.Tensor
    edge: torch.Tensor
    room: torch.Tensor
    turn: torch.Tensor
    axis: torch.Tensor
    half: torch.Tensor
    body: torch.Tensor
    rows: slice


def pack_tries(
    inner: Rect,
    footprints: Sequence,
    fixed: Occupants = NO_OCCUPANTS,
    tries: Sequence[tuple[PackConfig, int]] = ((PackConfig(), 0),),
    turnable: Sequence[bool] | None = None,
    walled: bool = True,
) -> list[PackResult]:
    """`pack` of the same footprints with each ``(config, seed)`` of ``tries``, all their
    restart rows optimised in one tensor program: each result is the one `pack` gives alone
    (a row's loss and its Adam step depend on that row only), and a batch of a few tries
    costs about what one does (a step's cost is mostly its fixed overhead). The tries may
    differ in their ``margin`` and ``restarts`` only. ``time``: the batch's, in each."""
    t0 = time.perf_counter()
    first = tries[0][0]
    for config, _ in tries:
        if replace(config, margin=first.margin, restarts=first.restarts) != first:
            raise PackError("tries packed together may differ in margin and restarts only")
    (x0, y0), (x1, y1) = inner
    half_np = fxy_np = fh_np = None
    made, u0, start = [], [], 0
    for config, seed in tries:
        inside = (
            (x0 + config.margin, y0 + config.margin),
            (x1 - config.margin, y1 - config.margin),
        )
        half_np, fxy_np, fh_np = _check(inside, footprints, fixed)
        made_try, start_u = _try(inside, half_np, (config, seed), turnable, walled, start)
        made.append(made_try)
        u0.append(start_u)
        start += config.restarts
    m = len(half_np)
    if m == 0:
        empty = np.zeros((0, 2))
        return [
            PackResult(empty, np.zeros(0), np.zeros(0, int), True, -math.inf, 0.0, 0) for _ in tries
        ]
    u = torch.cat(u0).requires_grad_(True)  # (sum R, M, 2)
    opt = Adam([{"params": [u], "lr": first.lr}])  # the planner's (no torch._dynamo import)
    fxy, fh = torch.from_numpy(fxy_np), torch.from_numpy(fh_np)
    lo = torch.cat([t.lo.expand(t.rows.stop - t.rows.start, 1, 2) for t in made])  # (sum R, 1, 2)
    edge, room = torch.cat([t.edge for t in made]), torch.cat([t.room for t in made])
    half, body = torch.cat([t.half for t in made]), torch.cat([t.body for t in made])
    steps = first.steps

    def centres() -> torch.Tensor:
        return lo + edge + room * torch.sigmoid(u)  # (sum R, M, 2)

    for k in range(steps):
        beta = first.beta * (first.beta_end / first.beta) ** (k / max(steps - 1, 1))
        loss = overlap_loss(centres(), half, body, fxy, fh, beta, first)
        opt.zero_grad()
        loss.sum().backward()
        opt.step()
    with torch.no_grad():
        xy = centres().numpy()  # (sum R, M, 2)
    took = time.perf_counter() - t0
    return [_best(t, xy[t.rows], fxy_np, fh_np, took) for t in made]


def _try(inside: Rect, half_np: np.ndarray, at: tuple, turnable, walled: bool, start: int):
    """One try of `pack_tries`, ``at`` its (config, seed), in the ``inside`` rectangle (its
    margin taken off), the footprints' half extents ``half_np`` (M, 2): its rows from
    ``start`` (their turns and closing axes drawn, the grown and body footprints, the room
    the centres may use) and their unbounded start values u (R, M, 2)."""
    config, seed = at
    m, r = len(half_np), config.restarts
    gen = torch.Generator().manual_seed(seed)
    square = np.isclose(half_np[:, 0], half_np[:, 1])
    may = ~square if turnable is None else np.asarray(turnable, dtype=bool)
    turn = (torch.rand(r, m, generator=gen) < 0.5) & torch.from_numpy(may)  # (R, M)
    axis = torch.randint(0, 2, (r, m), generator=gen)  # (R, M) closing axis per row
    h = torch.where(turn[..., None], torch.from_numpy(half_np).flip(-1), torch.from_numpy(half_np))
    wide = 2 * h.gather(-1, axis[..., None])[..., 0] >= config.stroke - 1e-6  # (R, M)
    axis = torch.where(wide, 1 - axis, axis)  # the fingers close across the other side
    body, half = _grown(torch.from_numpy(half_np), turn, axis, config)  # (R, M, 2)
    lo = torch.tensor(inside[0], dtype=torch.float64)
    span = torch.tensor(inside[1], dtype=torch.float64) - lo
    edge = half if walled else body  # what must stay inside: the hand too where walls stand
    room = (span - 2 * edge).clamp_min(0.0)  # (R, M, 2)
    u0 = torch.randn(r, m, 2, generator=gen, dtype=torch.float64)
    made = _Try(
        config=config,
        lo=lo,
        edge=edge,
        room=room,
        turn=turn,
        axis=axis,
        half=half,
        body=body,
        rows=slice(start, start + r),
    )
    return made, u0


def _best(t: _Try, xy: np.ndarray, fxy_np, fh_np, took: float) -> PackResult:
    """The winning row of one try (module docstring): the free row of least overlap that
    admits a placing order, else the row of least overlap."""
    config, m = t.config, xy.shape[1]
    fits = (t.room > 0).all(-1).all(-1).numpy()  # (R,) every grown footprint fits the region
    grown_np, body_np = t.half.numpy(), t.body.numpy()
    worst = _depths(xy, grown_np, body_np, fxy_np, fh_np, config.gap, config.ordered)  # (R,)
    worst = np.where(fits, worst, np.inf)
    best = int(np.argmin(worst))
    order = tuple(range(m))
    if config.ordered:
        # the free rows, least overlap first: the first with a placing order wins (the least
        # overlap alone may be a row no order can place)
        order = ()
        for row in [int(i) for i in np.argsort(worst, kind="stable") if worst[i] <= config.tol]:
            order = placing_order(xy[row], grown_np[row], body_np[row], config.gap, config.tol)
            if len(order) == m:
                best = row
                break
        if len(order) != m:
            order = placing_order(xy[best], grown_np[best], body_np[best], config.gap, config.tol)
    yaws = np.where(t.turn[best].numpy(), math.pi / 2, 0.0)
    return PackResult(
        positions=xy[best],
        yaws=yaws,
        axes=t.axis[best].numpy(),
        ok=bool(worst[best] <= config.tol) and len(order) == m,
        overlap=float(worst[best]),
        time=took,
        tries=config.restarts * config.steps,
        order=order,
    )


def pack_sampled(
    inner: Rect,
    footprints: Sequence,
    fixed: Occupants = NO_OCCUPANTS,
    budget: int = 1000,
    seed: int = 0,
    config: PackConfig = PackConfig(),
    per_object: int = 50,
    walled: bool = True,
) -> PackResult:
    """The sampled baseline (module docstring): at most ``budget`` position samples in all,
    ``per_object`` tries per object before starting over; each object's yaw (for a cuboid)
    and closing axis drawn at random per attempt; ``walled`` as in `pack`. Same result value
    as `pack` (``tries``: samples spent)."""
    t0 = time.perf_counter()
    (x0, y0), (x1, y1) = inner
    inner = ((x0 + config.margin, y0 + config.margin), (x1 - config.margin, y1 - config.margin))
    half_np, fxy_np, fh_np = _check(inner, footprints, fixed)
    m = len(half_np)
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(inner[0], float), np.asarray(inner[1], float)
    spent = 0
    best: PackResult | None = None
    while spent < budget:
        xy, yaws, axes = np.zeros((m, 2)), np.zeros(m), np.zeros(m, int)
        bodies, grown = np.zeros((m, 2)), np.zeros((m, 2))
        placed = 0
        for i in range(m):
            turn = not np.isclose(*half_np[i]) and rng.random() < 0.5
            axes[i] = rng.integers(2)
            bodies[i] = half_np[i][::-1] if turn else half_np[i]
            if 2 * bodies[i, axes[i]] >= config.stroke - 1e-6:
                axes[i] = 1 - axes[i]  # the fingers close across the other side
            grown[i] = np.maximum(bodies[i], config.side)
            grown[i, axes[i]] = max(bodies[i, axes[i]], config.fingers)
            yaws[i] = math.pi / 2 if turn else 0.0
            edge = grown[i] if walled else bodies[i]
            if np.any(hi - lo < 2 * edge):
                break
            for _ in range(per_object):
                if spent >= budget:
                    break
                spent += 1
                p = lo + edge + rng.random(2) * (hi - lo - 2 * edge)
                if _free(p, i, xy, grown, bodies, (fxy_np, fh_np), config):
                    xy[i] = p
                    placed += 1
                    break
            if placed <= i:
                break
        if placed == m:
            took = time.perf_counter() - t0
            return PackResult(
                positions=xy,
                yaws=yaws,
                axes=axes,
                ok=True,
                overlap=-math.inf,
                time=took,
                tries=spent,
                order=tuple(range(m)),
            )
        if best is None or placed > len(best.positions):
            best = PackResult(xy[:placed], yaws[:placed], axes[:placed], False, math.inf, 0.0, 0)
    if best is None:
        best = PackResult(np.zeros((0, 2)), np.zeros(0), np.zeros(0, int), False, math.inf, 0, 0)
    return PackResult(
        best.positions, best.yaws, best.axes, False, math.inf, time.perf_counter() - t0, spent
    )


def _free(p, i: int, xy, grown, bodies, fixed, config: PackConfig) -> bool:
    """Whether footprint ``i`` (grown and body half extents ``grown[i]``, ``bodies[i]``) at
    ``p`` clears the ones placed before it (both ways: the first ``i`` of ``xy``, ``grown``,
    ``bodies``) and the ``fixed`` ones (centres, half extents)."""
    grown, body, xy, others_grown, others_body = grown[i], bodies[i], xy[:i], grown[:i], bodies[:i]
    fxy, fh = fixed
    g, tol = config.gap, config.tol
    if len(xy):
        d = np.abs(xy - p)  # (k, 2)
        mine = (grown + others_body + g - d).min(-1)  # my hand against their bodies
        theirs = (others_grown + body + g - d).min(-1)  # theirs against mine (placed before me)
        if mine.max() > tol or (not config.ordered and theirs.max() > tol):
            return False
    return not (len(fxy) and (grown + fh + g - np.abs(fxy - p)).min(-1).max() > tol)
