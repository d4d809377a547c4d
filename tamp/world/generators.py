"""The six canonical problems' generators: each draws one variant's geometry from a seeded rng.

`GENERATORS` names them: `_blocked`, `_packed`, `_nonmonotonic`, `_sorting`, `_tall` and
`_hanoi` each return the objects, regions, obstacles, goal atoms, a note and a witness of one
draw (or None when the draw misses what makes the problem hard);
`tamp.world.canonical.generate` retries and checks them. Also the small helpers they share
(rounding, `round_length`; colours, zones) and `centre_first`, the naive packer ``packed``
must defeat.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from tamp.obstacles import Obstacle
from tamp.scene import PALETTE, Pose
from tamp.world.geometry import Solid, footprint_gap, of_box, of_movable
from tamp.world.hand import APPROACH, FINGER_OUT, REACH_EDGE, free_top_axes, top_reach
from tamp.world.schema import Movable, Region, Scene, Table

TABLE_TOP = Table((-0.3, -0.7), (1.0, 0.7))  # the shipped scenes' table
POST_HALF = (0.01, 0.01, 0.05)  # m, a sorting post: 2 x 2 cm, 10 cm tall (see `_sorting`)
KERB = (0.015, 0.016)  # m, the alcove's walls: thickness, height
TRIES = 200  # draws per variant before giving up (a generator bug, not bad luck)
COLOURS = ("red", "blue", "green", "yellow", "orange", "purple", "cyan", "magenta")


# ---- the centre-first greedy packer -------------------------------------------------------


def centre_first(
    scene: Scene, region: str, names: Sequence[str], step: float = 0.0025
) -> tuple[str, ...]:
    """Where a naive packer gets: each object of ``names`` in turn at the free spot of the
    region's inner rectangle nearest its centre (a ``step`` m grid, yaw 0 or a quarter turn,
    footprints only, no room for fingers). The names it placed, in order; fewer than
    ``names`` when it got stuck."""
    (x0, y0), (x1, y1) = scene.region(region).inner()
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    xs = np.arange(x0, x1 + 1e-9, step)
    ys = np.arange(y0, y1 + 1e-9, step)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")  # (X, Y)
    dist = np.hypot(gx - centre[0], gy - centre[1])  # (X, Y)
    placed: list[tuple[float, float, float, float]] = []  # (xlo, xhi, ylo, yhi)
    done = []
    for name in names:
        o = scene.object(name)
        best = None
        for ex, ey in ((o.half[0], o.half[1]), (o.half[1], o.half[0])):
            ok = (gx - ex >= x0 - 1e-9) & (gx + ex <= x1 + 1e-9)  # (X, Y)
            ok &= (gy - ey >= y0 - 1e-9) & (gy + ey <= y1 + 1e-9)
            for ax0, ax1, ay0, ay1 in placed:
                ok &= ~((gx + ex > ax0) & (gx - ex < ax1) & (gy + ey > ay0) & (gy - ey < ay1))
            if ok.any():
                i = np.unravel_index(np.where(ok, dist, np.inf).argmin(), dist.shape)
                if best is None or dist[i] < best[0] - 1e-12:
                    best = (dist[i], gx[i], gy[i], ex, ey)
        if best is None:
            break
        _, cx, cy, ex, ey = best
        placed.append((cx - ex, cx + ex, cy - ey, cy + ey))
        done.append(name)
    return tuple(done)


# ---- shared pieces -------------------------------------------------------------------------------

_Made = tuple  # (objects, regions, obstacles, goal atoms, note, witness)


def round_length(value: float) -> float:
    """A length rounded to 0.1 mm (files stay readable; every margin is millimetres)."""
    return round(float(value), 4) + 0.0


def _size(value: float) -> float:
    """A size rounded to 1 mm."""
    return round(float(value), 3) + 0.0


def _rgb(colour: str) -> tuple[float, float, float]:
    return dict(PALETTE)[colour]


def _movable(name, kind, size, colour: str, xyz, yaw: float = 0.0) -> Movable:
    size = tuple(_size(s) for s in size)
    return Movable(
        name, kind, size, _rgb(colour), Pose(tuple(round_length(v) for v in xyz), round_length(yaw))
    )


def _at(o: Movable, xyz, yaw: float | None = None) -> Movable:
    """``o`` moved to ``xyz`` (yaw kept unless given)."""
    yaw = o.pose.yaw if yaw is None else yaw
    return replace(o, pose=Pose(tuple(round_length(v) for v in xyz), round_length(yaw)))


def _zone(name: str, centre, side, colour: str) -> Region:
    """A marked rectangle (no floor, no walls) of ``side`` (sx, sy) m around ``centre``."""
    (cx, cy), (sx, sy) = centre, side
    lo, hi = (
        (round_length(cx - sx / 2), round_length(cy - sy / 2)),
        (round_length(cx + sx / 2), round_length(cy + sy / 2)),
    )
    return Region(name, lo, hi, rgb=_rgb(colour))


def _polar(r: float, theta: float) -> tuple[float, float]:
    return r * math.cos(theta), r * math.sin(theta)


def _rot(yaw: float, u: float, v: float) -> tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * u - s * v, s * u + c * v


def _clear_of(solid: Solid, others, gap: float) -> bool:
    """True when ``solid``'s footprint keeps ``gap`` m from every one of ``others``."""
    return all(footprint_gap(solid, s) >= gap for s in others)


def _in_zone(o: Movable, zones: Sequence[Region], margin: float) -> bool:
    """True when ``o``'s footprint comes within ``margin`` of any of ``zones``."""
    me = of_movable(o)
    for r in zones:
        box = Solid(
            r.name,
            False,
            ((r.lo[0] + r.hi[0]) / 2, (r.lo[1] + r.hi[1]) / 2, 0.0),
            ((r.hi[0] - r.lo[0]) / 2, (r.hi[1] - r.lo[1]) / 2, 1.0),
        )
        if footprint_gap(me, box) < margin:
            return True
    return False


# ---- the six problems ----------------------------------------------------------------------------


def _blocked(rng: np.random.Generator, n: int) -> _Made | None:
    """The target cube with n neighbours along its faces, 4-8 mm away, as tall as it or a few
    mm taller; with 3 the open side leaves one axis blocked only by the opposite neighbour."""
    colours = [str(c) for c in rng.permutation(COLOURS)]
    s = _size(rng.uniform(0.045, 0.05))
    r, theta = rng.uniform(0.45, 0.56), rng.uniform(-0.45, 0.45)
    cx, cy = _polar(r, theta)
    yaw = rng.uniform(-math.pi / 4, math.pi / 4)
    target = _movable("t", "cube", (s,), colours[0], (cx, cy, s / 2), yaw)
    sides = [(1, 0), (-1, 0), (0, 1), (0, -1)]
    open_side = None
    if n == 3:
        open_side = sides[int(rng.integers(4))]
        sides.remove(open_side)
    objects = [target]
    for k, (du, dv) in enumerate(sides, start=1):
        depth = _size(rng.uniform(0.04, 0.05))
        across = depth if rng.random() < 0.4 else _size(rng.uniform(0.045, 0.06))
        h = _size(rng.uniform(s, s + 0.004))
        gap = rng.uniform(0.004, 0.008)
        off = s / 2 + gap + depth / 2
        ox, oy = _rot(yaw, du * off, dv * off)
        size = (depth, across, h) if du else (across, depth, h)
        kind = "cube" if depth == across == h else "cuboid"
        size = (depth,) if kind == "cube" else size
        objects.append(_movable(f"n{k}", kind, size, colours[k], (cx + ox, cy + oy, h / 2), yaw))
    gtheta = theta - math.copysign(rng.uniform(0.75, 0.95), theta if theta else 1.0)
    zone = _zone("goal_zone", _polar(rng.uniform(0.45, 0.55), gtheta), (0.12, 0.12), "white")
    scene = Scene("draft", TABLE_TOP, (zone,), (), tuple(objects))
    if free_top_axes(scene, "t", pad=-0.003):
        return None
    if not all(free_top_axes(scene, o.name, pad=0.004) for o in objects[1:]):
        return None
    if n == 3:  # moving the neighbour opposite the open side frees the target
        du, dv = open_side
        opposite = f"n{sides.index((-du, -dv)) + 1}"
        if not free_top_axes(scene, "t", pad=0.004, without=(opposite,)):
            return None
        why = f"until {opposite}, opposite the open side, moves"
    else:
        why = "until two opposite neighbours move"
    note = (
        f"target t hemmed in by {n} neighbours 4-8 mm away (a finger is 2.4 cm thick): "
        f"no top-down grasp is collision-free {why}"
    )
    return objects, (zone,), (), [("in", "t", "goal_zone")], note, ()


def _packed(rng: np.random.Generator, n: int) -> _Made | None:
    """n boxes of one width and several lengths; the tray fits them as two columns along y
    of equal length with a finger lane between; the objects start spread out on the other
    side."""
    colours = [str(c) for c in rng.permutation(COLOURS)]
    w = _size(rng.uniform(0.055, 0.062))
    heights = [_size(rng.uniform(0.04, 0.055)) for _ in range(n)]
    gap_y, margin = 0.004, 0.002
    first = (n + 1) // 2
    longest = 0.085 if n % 2 == 0 else 0.07  # odd n: the column of fewer is as long
    lengths = [_size(rng.uniform(0.055, longest)) for _ in range(first)]
    rest = sum(lengths) + gap_y * (first - 1) - gap_y * (n - first - 1)  # the other column's
    shares = rng.dirichlet([4.0] * (n - first))  # (n - first,) its boxes' shares, near even
    lengths += [_size(0.055 + (rest - 0.055 * (n - first)) * f) for f in shares]
    lengths[-1] = _size(rest - sum(lengths[first:-1]))  # the column adds up after rounding
    if max(lengths) > 0.12:
        return None
    columns = [list(range(first)), list(range(first, n))]
    span = [sum(lengths[j] for j in c) + gap_y * (len(c) - 1) for c in columns]
    pitch = FINGER_OUT + 0.006 + w / 2  # column centres: a finger lane between the columns
    width = w + pitch + 2 * margin
    height = max(span) + 2 * margin + rng.uniform(0.0, 0.01)
    side = 1.0 if rng.random() < 0.5 else -1.0
    tx, ty = rng.uniform(0.48, 0.53), side * rng.uniform(0.17, 0.2)
    tray = _zone("tray", (tx, ty), (width, height), "brown")
    (x0, y0), _ = tray.inner()
    objects, witness = [], []
    starts = [(x, -side * y) for y in (0.12, 0.26, 0.40) for x in (0.42, 0.56)]
    order = rng.permutation(len(starts))
    for i in range(n):
        kind = "cuboid" if abs(lengths[i] - w) > 1e-9 or abs(heights[i] - w) > 1e-9 else "cube"
        sx, sy = starts[order[i]]
        jx, jy = rng.uniform(-0.01, 0.01, 2)
        yaw = rng.uniform(-0.3, 0.3)
        size = (w, lengths[i], heights[i])
        objects.append(
            _movable(f"o{i + 1}", kind, size, colours[i % len(colours)], (sx + jx, sy + jy, 0), yaw)
        )
        objects[-1] = _at(objects[-1], (sx + jx, sy + jy, objects[-1].half[2]))
    for c, col in enumerate(columns):
        x = x0 + margin + w / 2 + c * pitch
        y = y0 + margin + (height - 2 * margin - span[c]) / 2
        for j in col:
            o = objects[j]
            witness.append(
                (o.name, Pose((round_length(x), round_length(y + o.half[1]), o.pose.xyz[2]), 0.0))
            )
            y += 2 * o.half[1] + gap_y
    footprint = sum(4 * o.half[0] * o.half[1] for o in objects)
    (ix0, iy0), (ix1, iy1) = tray.inner()
    fill = footprint / ((ix1 - ix0) * (iy1 - iy0))
    if not 0.6 <= fill <= 0.75:
        return None
    staged = Scene("draft", TABLE_TOP, (tray,), (), tuple(objects))
    if not all(free_top_axes(staged, o.name, pad=0.004) for o in objects):
        return None
    done = dict(witness)
    packed = Scene(
        "draft", TABLE_TOP, (tray,), (), tuple(_at(o, done[o.name].xyz, 0.0) for o in objects)
    )
    if not all(free_top_axes(packed, o.name, pad=0.003) for o in objects):
        return None
    names = [o.name for o in objects]
    biggest = sorted(names, key=lambda m: -packed.object(m).half[1])
    if len(centre_first(packed, "tray", biggest)) == n:
        return None
    if len(centre_first(packed, "tray", names)) == n:
        return None
    note = (
        f"{n} boxes fill {fill:.0%} of the tray: they fit only as two columns with a finger "
        "lane between; the first box at the centre leaves no room for the last"
    )
    atoms = [("in", o.name, "tray") for o in objects]
    return objects, (tray,), (), atoms, note, witness


def _nonmonotonic(rng: np.random.Generator, n: int) -> _Made | None:
    """A kerbed alcove along +x, open towards the robot: the wide, low target at its back with
    room behind it, n tall narrow front objects in a row before it, 5-8 mm apart."""
    colours = [str(c) for c in rng.permutation(COLOURS)]
    cy = rng.uniform(-0.1, 0.1)
    mouth = rng.uniform(0.38, 0.42)
    bx, by = _size(rng.uniform(0.045, 0.05)), _size(rng.uniform(0.066, 0.07))
    bh = _size(rng.uniform(0.03, 0.034))
    inner = by + 2 * rng.uniform(0.005, 0.008)  # the alcove's inner width
    fh = _size(rng.uniform(0.062, 0.066))
    fronts = []
    x = mouth + rng.uniform(0.005, 0.01)
    sizes = [(_size(rng.uniform(0.035, 0.04)), _size(rng.uniform(0.035, 0.04))) for _ in range(n)]
    for k in range(n, 0, -1):  # from the mouth inwards: f_n first, f1 last (next to t)
        fx, fy = sizes[k - 1]
        x += fx / 2
        dy = rng.uniform(-0.002, 0.002)
        fronts.append(_movable(f"f{k}", "cuboid", (fx, fy, fh), colours[k], (x, cy + dy, fh / 2)))
        x += fx / 2 + rng.uniform(0.005, 0.008)
    target = _movable("t", "cuboid", (bx, by, bh), colours[0], (x + bx / 2, cy, bh / 2))
    back = x + bx + rng.uniform(0.048, 0.052)  # the back kerb's inner face
    t, h = KERB
    length = back - mouth
    walls = (
        Obstacle(
            "kerb_back",
            (round_length(back + t / 2), round_length(cy), h / 2),
            (t / 2, round_length(inner / 2 + t), h / 2),
        ),
        Obstacle(
            "kerb_left",
            (round_length(mouth + length / 2), round_length(cy + inner / 2 + t / 2), h / 2),
            (round_length(length / 2), t / 2, h / 2),
        ),
        Obstacle(
            "kerb_right",
            (round_length(mouth + length / 2), round_length(cy - inner / 2 - t / 2), h / 2),
            (round_length(length / 2), t / 2, h / 2),
        ),
    )
    alcove = Region(
        "alcove",
        (round_length(mouth), round_length(cy - inner / 2)),
        (round_length(back), round_length(cy + inner / 2)),
        rgb=_rgb("white"),
    )
    gtheta = -math.copysign(rng.uniform(0.6, 0.8), cy if cy else 1.0)
    zone = _zone("goal_zone", _polar(rng.uniform(0.45, 0.52), gtheta), (0.12, 0.12), "brown")
    objects = [target, *reversed(fronts)]
    scene = Scene("draft", TABLE_TOP, (alcove, zone), walls, tuple(objects))
    if free_top_axes(scene, "t", pad=-0.003):
        return None
    if not all(free_top_axes(scene, f.name, pad=0.004) for f in fronts):
        return None
    blockers = ("f1", "f2")
    if free_top_axes(scene, "t", pad=-0.003, without=("f1",)):
        return None
    if not free_top_axes(scene, "t", pad=0.004, without=blockers):
        return None
    note = (
        f"target t at the back of a kerbed alcove behind {n} objects: f1 blocks its fingers, "
        "f2 its palm; both must go out and come back"
    )
    atoms = [("in", "t", "goal_zone"), *(("in", f"f{k}", "alcove") for k in range(1, n + 1))]
    return objects, (alcove, zone), walls, atoms, note, ()


def _sorting(rng: np.random.Generator, n: int, colours: int) -> _Made | None:
    """n objects scattered over a sector in front of the robot, each with a post 4.5-6 cm
    from its centre that blocks one of its two top-down grasp axes; a zone per colour on
    the sides, sized for its objects; a few free posts between. The posts are 10 cm tall:
    they block the hand and fingers the reference hand models (`tamp.world.hand`), and stay
    below the wrist (at 15 cm the Panda's last link came within 2 mm of the post beside the
    free axis, so 3 of 20 seeded variants had an object no grasp could pick)."""
    names = [str(c) for c in rng.permutation(("red", "blue", "green", "yellow"))[:colours]]
    of = [names[i % colours] for i in range(n)]
    of = [of[i] for i in rng.permutation(n)]
    angles = {2: (-1.0, 1.0), 3: (-1.65, -1.05, 1.05)}[colours]
    zones = []
    for c, a in zip(names, angles, strict=True):
        count = of.count(c)
        side = {1: 0.12, 2: 0.12, 3: 0.16}.get(count, 0.2)
        zones.append(_zone(f"{c}_zone", _polar(0.5, a), (side, side), c))
    objects: list[Movable] = []
    posts: list[Obstacle] = []
    blocked: dict[str, int] = {}
    for i in range(n):
        for _ in range(TRIES):
            o, drawn = _sorting_object(rng, f"o{i + 1}", of[i])
            axis, mine = _posts_beside(rng, drawn, len(posts))
            solids = [of_movable(p) for p in objects] + [of_box(p) for p in posts]
            new = [of_movable(o)] + [of_box(p) for p in mine]
            if not all(_clear_of(s, solids, 0.03) for s in new):
                continue
            if _in_zone(o, zones, 0.03) or any(
                math.hypot(*p.centre[:2]) > 0.7 or math.hypot(*p.centre[:2]) < 0.3 for p in mine
            ):
                continue
            if _sorted_grasps(zones, [*posts, *mine], [*objects, o], blocked | {o.name: axis}):
                objects.append(o)
                posts += mine
                blocked[o.name] = axis
                break
        else:
            return None
    for _ in range(n // 2):  # free posts between the objects
        post = _free_post(rng, zones, posts, objects, blocked)
        if post is not None:
            posts.append(post)
    note = (
        f"{n} objects of {colours} colours among {len(posts)} posts 10 cm tall: a post 4.5-6 cm "
        "from each object blocks one of its two top-down grasp axes"
    )
    atoms = [("in", o.name, f"{c}_zone") for o, c in zip(objects, of, strict=True)]
    return objects, tuple(zones), tuple(posts), atoms, note, ()


def _sorting_object(rng: np.random.Generator, name: str, colour: str):
    """An object of ``colour`` of a random kind and size, somewhere in the sector in front of
    the robot, turned up to 45 degrees, standing on the table; and the (x, y, yaw) drawn for
    it, before the object's own rounding."""
    r, theta = rng.uniform(0.36, 0.66), rng.uniform(-0.65, 0.65)
    x, y = _polar(r, theta)
    yaw = rng.uniform(-math.pi / 4, math.pi / 4)
    kind = str(rng.choice(("cube", "cuboid", "cylinder")))
    if kind == "cube":
        size = (rng.uniform(0.045, 0.05),)
    elif kind == "cuboid":
        size = (
            rng.uniform(0.045, 0.05),
            rng.uniform(0.05, 0.065),
            rng.uniform(0.045, 0.06),
        )
    else:
        size = (rng.uniform(0.045, 0.05), rng.uniform(0.05, 0.06))
    o = _movable(name, kind, size, colour, (x, y, 0.0), yaw)
    return _at(o, (x, y, o.half[2])), (x, y, yaw)


def _posts_beside(rng: np.random.Generator, at: tuple, first: int) -> tuple[int, list]:
    """The grasp axis (0 or 1, in the frame of an object at ``at``, (x, y, yaw)) to block and
    the posts, numbered from ``first``, that block it: one 4.5-6 cm from the object's centre
    on a random side, or (three times in ten) one on each side."""
    x, y, yaw = at
    axis = int(rng.integers(2))
    signs = (1.0, -1.0) if rng.random() < 0.3 else (float(rng.choice((1.0, -1.0))),)
    mine = []
    for s in signs:
        d = rng.uniform(0.046, 0.056) + POST_HALF[0]
        across = rng.uniform(-0.003, 0.003)
        u, v = (s * d, across) if axis == 0 else (across, s * d)
        px, py = _rot(yaw, u, v)
        mine.append(
            Obstacle(
                f"post_{first + len(mine)}",
                (round_length(x + px), round_length(y + py), POST_HALF[2]),
                POST_HALF,
                round_length(yaw),
            )
        )
    return axis, mine


def _free_post(rng: np.random.Generator, zones, posts: list, objects: list, blocked: dict):
    """A post clear of the ``objects`` and the ``posts`` that leaves every object's grasps
    as ``blocked`` says, in at most 20 draws in the sector; None when none fits."""
    for _ in range(20):
        x, y = _polar(rng.uniform(0.36, 0.66), rng.uniform(-0.65, 0.65))
        post = Obstacle(
            f"post_{len(posts)}", (round_length(x), round_length(y), POST_HALF[2]), POST_HALF
        )
        solid = of_box(post)
        if (
            _clear_of(solid, [of_movable(o) for o in objects], 0.03)
            and _clear_of(solid, [of_box(p) for p in posts], 0.04)
            and _sorted_grasps(zones, [*posts, post], objects, blocked)
        ):
            return post
    return None


def _sorted_grasps(zones, posts, objects, blocked: dict[str, int]) -> bool:
    """True when each object's top-down grasps are free along the axis ``blocked`` does not
    name (with a 4 mm margin) and blocked along the one it names (even 3 mm thinner), and
    only the posts block it: without them both axes are free."""
    scene = Scene("draft", TABLE_TOP, tuple(zones), tuple(posts), tuple(objects))
    bare = replace(scene, obstacles=())
    for o in objects:
        if free_top_axes(bare, o.name) != (0, 1):
            return False
        if free_top_axes(scene, o.name, pad=0.004) != (1 - blocked[o.name],):
            return False
        if blocked[o.name] in free_top_axes(scene, o.name, pad=-0.003):
            return False
    return True


def _tall(rng: np.random.Generator, n: int, mode: str) -> _Made | None:
    """n cubes: ``down``, a tower at the edge of reach rebuilt upside down on a near pad;
    ``build``, three short stacks near the robot built into one tower on a far pad."""
    colours = [COLOURS[i % len(COLOURS)] for i in rng.permutation(n)]
    top_max = top_reach(0.655) - APPROACH - 0.02  # the tallest tower reachable at 0.655 m
    s = _size(rng.uniform(0.038, min(0.045, top_max / n)))
    top = n * s
    r_max = min(0.70, REACH_EDGE[0] + (REACH_EDGE[1] - APPROACH - 0.02 - top) / REACH_EDGE[2])
    r = rng.uniform(0.65, r_max)
    theta = rng.uniform(-0.45, 0.45)
    fx, fy = _polar(r, theta)
    ntheta = theta - math.copysign(rng.uniform(0.6, 0.85), theta if theta else 1.0)
    near = _polar(rng.uniform(0.42, 0.48), ntheta)
    names = [f"c{i + 1}" for i in range(n)]
    pad_side = (s + 0.04, s + 0.04)
    if mode == "down":
        yaw = rng.uniform(-0.4, 0.4)
        objects = []
        for i, name in enumerate(names):
            jx, jy = rng.uniform(-0.002, 0.002, 2)
            z = s / 2 + i * s
            objects.append(
                _movable(
                    name,
                    "cube",
                    (s,),
                    colours[i],
                    (fx + jx, fy + jy, z),
                    yaw + rng.uniform(-0.05, 0.05),
                )
            )
        pad = _zone("near_pad", near, pad_side, "white")
        chain = list(reversed(names))  # bottom first: the old top at the bottom
        note = (
            f"a {n}-cube tower ({top:.2f} m) {r:.2f} m out, at the edge of the arm's reach, "
            "to rebuild upside down on a near pad"
        )
        atoms = [("in", chain[0], "near_pad")]
    else:
        sizes = [n // 3 + (1 if k < n % 3 else 0) for k in range(3)]
        away = -math.copysign(1.0, theta if theta else 1.0)
        spots = [_polar(0.45, theta + away * a) for a in (0.55, 0.85, 1.15)]
        objects, i = [], 0
        for (x, y), count in zip(spots, sizes, strict=True):
            yaw = rng.uniform(-0.4, 0.4)
            for level in range(count):
                objects.append(
                    _movable(names[i], "cube", (s,), colours[i], (x, y, s / 2 + level * s), yaw)
                )
                i += 1
        pad = _zone("far_pad", (fx, fy), pad_side, "white")
        chain = [names[i] for i in rng.permutation(n)]
        note = (
            f"build a {n}-cube tower ({top:.2f} m) on a pad {r:.2f} m out: its top cubes go "
            "where top-down reach runs out"
        )
        atoms = [("in", chain[0], "far_pad")]
    atoms += [("on", chain[k + 1], chain[k]) for k in range(n - 1)]
    return objects, (pad,), (), atoms, note, ()


def _hanoi(rng: np.random.Generator, n: int) -> _Made | None:
    """n square discs (widths evenly from ~4 to ~6.7 cm, each 2.4-2.8 cm thick) stacked on
    peg1 of three marked pegs 15-17 cm apart in a row across the robot's view. A peg is only
    6-10 mm wider than the largest disc, so no two discs fit in it side by side (two squares
    fit in a square only when their sides add up to at most its side): every peg holds one
    tower, as a peg does. Square, not round: two discs fit in a square diagonally when their
    diameters add up to 1.17 of its side, and a square disc rests wholly on a wider one."""
    widths = np.linspace(rng.uniform(0.04, 0.042), rng.uniform(0.065, 0.067), n)
    h = _size(rng.uniform(0.024, 0.028))
    x0, y0 = rng.uniform(0.46, 0.54), rng.uniform(-0.03, 0.03)
    pitch = rng.uniform(0.15, 0.17) * (1.0 if rng.random() < 0.5 else -1.0)
    side = _size(max(widths) + rng.uniform(0.006, 0.01))
    pegs = tuple(
        _zone(f"peg{k + 1}", (x0, y0 + (k - 1) * pitch), (side, side), "white") for k in range(3)
    )
    colours = [str(c) for c in rng.permutation(COLOURS)]
    cx, cy = (pegs[0].lo[0] + pegs[0].hi[0]) / 2, (pegs[0].lo[1] + pegs[0].hi[1]) / 2
    objects = []
    for level, i in enumerate(range(n, 0, -1)):  # the largest (d_n) at the bottom
        w = _size(widths[i - 1])
        jx, jy = rng.uniform(-0.001, 0.001, 2)
        z = h / 2 + level * h
        yaw = rng.uniform(-0.02, 0.02)
        objects.append(
            _movable(f"d{i}", "cuboid", (w, w, h), colours[i - 1], (cx + jx, cy + jy, z), yaw)
        )
    objects.reverse()  # d1 .. dn
    atoms = [("in", f"d{n}", "peg3"), *(("on", f"d{i}", f"d{i + 1}") for i in range(1, n))]
    note = (
        f"{n} discs from peg1 to peg3 ({2**n - 1} moves at best): a disc goes only on a wider "
        "one or an empty peg, which holds no two side by side"
    )
    return objects, pegs, (), atoms, note, ()


# problem name -> its generator: (rng, **the variant's drawn parameters) -> `_Made` | None
GENERATORS = {
    "blocked": _blocked,
    "packed": _packed,
    "nonmonotonic": _nonmonotonic,
    "sorting": _sorting,
    "tall": _tall,
    "hanoi": _hanoi,
}
