"""The scene model: a symbolic Blocksworld state <-> block poses on a table, and back.

Blocks are cubes (5 cm by default), or upright cylinders as tall as they are wide, with distinct
colours from the scene's palette; ``SceneConfig.bodies`` may give any entity its own solid
(`Body`: a cube, cuboid or cylinder of any size), which the simulators build. Each tower stands
on a *table slot*, a fixed grid of positions in front of the robot; a block moved onto the table
goes to a free slot, or to the place a plan named for it (`PlacedMove`, made by `plain_move`
from a move onto a planner's table place, `tamp.slots`). ``layout`` turns a state into poses
(with small seeded jitter). Observed poses are read back into a state by the one scene reader
(`tamp.world.convert.from_poses.read_state`, the support projection of `tamp.world.read_facts`).

World frame = the robot base frame (``panda_link0``); the table surface is z = 0.
"""

from __future__ import annotations

import colorsys
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from motion.grasps import KINDS
from task.errors import ProblemError, TampError, one_of
from task.problem import TABLE, Move

# PlanBench names a..e after red, blue, orange, yellow and white blocks; white is replaced by
# green here, because a white block cannot be told from the light-grey Panda by colour. The
# first ``CAMERA_COLOURS`` have hues at least 24 degrees apart, so camera perception can find
# them by colour; brown (an orange hue) and white are for larger state-observed scenes only.
PALETTE: tuple[tuple[str, tuple[float, float, float]], ...] = (
    ("red", (0.85, 0.1, 0.1)),
    ("blue", (0.1, 0.25, 0.9)),
    ("orange", (1.0, 0.55, 0.05)),
    ("yellow", (0.95, 0.9, 0.1)),
    ("green", (0.1, 0.7, 0.2)),
    ("purple", (0.55, 0.2, 0.75)),
    ("cyan", (0.1, 0.8, 0.85)),
    ("magenta", (0.95, 0.3, 0.75)),
    ("brown", (0.5, 0.3, 0.1)),
    ("white", (0.95, 0.95, 0.95)),
)
CAMERA_COLOURS = 8  # blocks that camera perception can tell apart by colour
SHAPES = ("cube", "cylinder")
BODY_KINDS = KINDS  # the solids the grasps know (`motion.grasps.KINDS`)
XY = tuple[float, float]  # a position on the table (x, y), m


class SceneError(TampError):
    """A state cannot be laid out (too many blocks, too tall) or a pose is malformed."""


@dataclass(frozen=True)
class Pose:
    """A block pose: centre position (m) and yaw about the vertical (rad)."""

    xyz: tuple[float, float, float]
    yaw: float = 0.0

    @property
    def xy(self) -> np.ndarray:
        return np.asarray(self.xyz[:2])


@dataclass(frozen=True)
class Body:
    """One movable object's solid: ``kind`` (one of `BODY_KINDS`) and its half extents (m) in
    the object's frame, centre at the origin, z up; a cylinder stands upright with
    ``half = (r, r, h / 2)``."""

    kind: str
    half: tuple[float, float, float]

    def __post_init__(self) -> None:
        if self.kind not in BODY_KINDS:
            raise SceneError(f"unknown body kind {one_of(self.kind, BODY_KINDS)}")
        if len(self.half) != 3 or not all(math.isfinite(h) and h > 0 for h in self.half):
            raise SceneError(f"body half extents must be three positive numbers, got {self.half}")
        if self.kind == "cylinder" and self.half[0] != self.half[1]:
            raise SceneError(f"a cylinder's half extents are (r, r, h / 2), got {self.half}")
        if self.kind == "cube" and len(set(self.half)) != 1:
            raise SceneError(f"a cube's half extents are equal, got {self.half}")

    @property
    def volume(self) -> float:
        """m^3."""
        hx, hy, hz = self.half
        if self.kind == "cylinder":
            return math.pi * hx * hx * 2 * hz
        return 8 * hx * hy * hz


@dataclass(frozen=True)
class SceneConfig:
    """Geometry of the table scene. Slots form a grid of ``slot_xs`` x ``slot_ys``.

    The default is the robot's cube scene; `tamp.camera.latplan` builds LatPlan's cylinder row.
    """

    block_size: float = 0.05  # cube edge, or a cylinder's height and diameter, m
    block_mass: float = 0.1  # kg
    # 16 cm apart: the open hand (about 20 cm across) clears a neighbouring tower
    slot_xs: tuple[float, ...] = (0.40, 0.56)
    slot_ys: tuple[float, ...] = (-0.32, -0.16, 0.0, 0.16, 0.32)
    jitter_xy: float = 0.004  # uniform +-, m
    jitter_yaw: float = 0.15  # uniform +-, rad
    max_height: int = 7  # blocks per tower the arm can still clear
    tol_xy: float = 0.02  # the executor's checks: a block stacked on another is centred this close
    # a bottom this close to a face rests on it (the loop's state reader, `tamp.world.geometry.
    # loop_tolerances`; the executor's checks: heights differ by one block size within this)
    tol_z: float = 0.012
    slot_radius: float = 0.05  # a slot is occupied when a block centre lies this close
    isolation: float = 0.3  # free_slot prefers slots with this much room to every block
    shape: str = "cube"  # one of SHAPES; a cylinder stands upright
    palette: tuple[tuple[str, tuple[float, float, float]], ...] = PALETTE  # block i: palette[i]
    floor_grey: float = 0.45  # RGB level of the floor, in [0, 1]
    backdrop_y: float | None = None  # a vertical backdrop wall across the view at this y, m
    backdrop_grey: float = 0.45
    obstacles: tuple = ()  # fixed boxes (`tamp.obstacles.Obstacle`); see tamp.obstacles.SCENES
    # flat boxes drawn but never collided with (`tamp.obstacles.Obstacle`): the marks of regions
    # without walls (`tamp.world.load.scene_config`), so cameras see them
    marks: tuple = ()
    name: str = "tabletop"  # the named scene the obstacles come from
    # each listed entity's own solid (`Body`); an entity not listed is the default block
    bodies: tuple[tuple[str, Body], ...] = ()

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise SceneError(f"unknown block shape {one_of(self.shape, SHAPES)}")

    @property
    def default_body(self) -> Body:
        """The scene's block: a cube of ``block_size``, or an upright cylinder as tall as wide."""
        half = self.block_size / 2
        return Body(self.shape, (half, half, half))

    def body(self, name: str) -> Body:
        """The solid of entity ``name``: its entry in ``bodies``, else `default_body`."""
        for key, body in self.bodies:
            if key == name:
                return body
        return self.default_body

    @property
    def slots(self) -> tuple[tuple[float, float], ...]:
        return tuple((x, y) for x in self.slot_xs for y in self.slot_ys)

    def capacity(self, slot: Sequence[float]) -> int:
        """Blocks a tower on ``slot`` (x, y) may have: ``max_height``, or fewer under an
        overhead obstacle (`tamp.obstacles.slot_capacity`)."""
        if not self.obstacles:
            return self.max_height
        from tamp.obstacles import slot_capacity

        limit = slot_capacity(slot, self.obstacles, self.block_size)
        return self.max_height if limit is None else min(limit, self.max_height)


def cube_yaw(rotation) -> float:
    """Yaw of a cube's side faces from its rotation matrix (3, 3), in [-pi/4, pi/4): the axis
    after the one most nearly up, projected on the table (right for a cube on its side too)."""
    r = np.asarray(rotation, dtype=float).reshape(3, 3)  # columns: block axes in the world
    up = int(np.argmax(np.abs(r[2])))
    side = r[:, (up + 1) % 3]
    quarter = math.pi / 2
    return (math.atan2(side[1], side[0]) + quarter / 2) % quarter - quarter / 2


def colour(index: int, palette=PALETTE) -> tuple[float, float, float]:
    """RGB in [0, 1] of the block at ``index`` in entity order; beyond the palette, golden-ratio
    hues (the camera, which tells blocks by colour, refuses over `CAMERA_COLOURS` blocks)."""
    if index < len(palette):
        return palette[index][1]
    hue, value = (index * 0.618034) % 1.0, 0.85 if index % 2 else 0.55
    return tuple(float(c) for c in colorsys.hsv_to_rgb(hue, 0.75, value))


def towers(entities: Sequence[str], state: Sequence[str]) -> list[list[str]]:
    """Bottom-to-top towers of a crisp state (supports in ``entities`` order)."""
    support = dict(zip(entities, state, strict=True))
    above = {sup: x for x, sup in support.items() if sup != TABLE}
    out = []
    for base in (x for x in entities if support[x] == TABLE):
        tower = [base]
        while tower[-1] in above:
            tower.append(above[tower[-1]])
        out.append(tower)
    if sum(len(t) for t in out) != len(entities):
        raise ProblemError("the state has a support cycle or two blocks on one block")
    return out


def layout(
    entities: Sequence[str],
    state: Sequence[str],
    config: SceneConfig = SceneConfig(),
    seed: int = 0,
    slots: Sequence[int] | None = None,
) -> dict[str, Pose]:
    """Poses for a crisp state: towers on random slots (or tower i, in `towers` order, on slot
    ``slots[i]`` of ``config.slots``), stacked exactly, jittered in xy and yaw. One slot always
    stays free (a move to the table needs one), so at most ``len(config.slots) - 1`` towers."""
    stacks = towers(entities, state)
    if len(stacks) > len(config.slots) - 1:
        k = len(config.slots)
        raise SceneError(
            f"{len(stacks)} towers leave no free table slot: the scene has {k} slots and keeps "
            f"one free for moves to the table (at most {k - 1} towers)"
        )
    if max(len(t) for t in stacks) > config.max_height:
        raise SceneError(f"a tower is taller than {config.max_height} blocks")
    rng = np.random.default_rng(seed)
    s = config.block_size
    order = rng.permutation(len(config.slots))[: len(stacks)]
    if config.obstacles and slots is None:  # each tower on a slot with room for it
        order = _fit(stacks, rng.permutation(len(config.slots)), config)
    if slots is not None:
        if len(slots) != len(stacks) or len(set(slots)) != len(slots):
            raise SceneError(f"slots must give each of the {len(stacks)} towers its own slot")
        if any(not 0 <= k < len(config.slots) for k in slots):
            raise SceneError(f"slot indices must lie in 0..{len(config.slots) - 1}, got {slots}")
        order = slots
    poses = {}
    for tower, k in zip(stacks, order, strict=True):
        sx, sy = config.slots[k]
        for level, x in enumerate(tower):
            dx, dy = rng.uniform(-config.jitter_xy, config.jitter_xy, size=2)
            yaw = float(rng.uniform(-config.jitter_yaw, config.jitter_yaw))
            poses[x] = Pose((sx + dx, sy + dy, s / 2 + level * s), yaw)
    return poses


def _fit(stacks: list[list[str]], order: np.ndarray, config: SceneConfig) -> list[int]:
    """Slots (in ``order``'s preference) for the towers, tallest first, each within capacity."""
    chosen: dict[int, int] = {}
    for i in sorted(range(len(stacks)), key=lambda i: -len(stacks[i])):
        room = [k for k in order if k not in chosen.values()]
        fits = [k for k in room if config.capacity(config.slots[k]) >= len(stacks[i])]
        if not fits:
            raise SceneError(
                f"no slot of scene {config.name!r} has room for a tower of {len(stacks[i])} blocks"
            )
        chosen[i] = int(fits[0])
    return [chosen[i] for i in range(len(stacks))]


def top_z(poses: Mapping[str, Pose], config: SceneConfig = SceneConfig()) -> float:
    """Height of the highest block top in the scene (0 for an empty table)."""
    return max((p.xyz[2] + config.block_size / 2 for p in poses.values()), default=0.0)


def free_slot(
    poses: Mapping[str, Pose], near: Sequence[float], config: SceneConfig = SceneConfig()
) -> tuple[float, float] | None:
    """The best unoccupied table slot (the first of `free_slots`), or None when all are taken."""
    slots = free_slots(poses, near, config)
    return slots[0] if slots else None


def free_slots(
    poses: Mapping[str, Pose], near: Sequence[float], config: SceneConfig = SceneConfig()
) -> list[tuple[float, float]]:
    """Unoccupied table slots, best first (the arm tries the next when it cannot reach one).

    Slots away from every block come first (a slot next to a tower puts the arm's wrist beside
    that tower, which it can knock over); among those with ``isolation`` m of room, the ones
    nearest to ``near`` (x, y).
    """

    def room(slot) -> float:
        return min((math.dist(slot, p.xy) for p in poses.values()), default=math.inf)

    free = [
        slot
        for slot in config.slots
        if room(slot) > config.slot_radius and config.capacity(slot) > 0
    ]
    # unlimited slots before those under an overhead obstacle, when both are as isolated
    return sorted(
        free,
        key=lambda s: (
            -min(room(s), config.isolation),
            config.capacity(s) < config.max_height,
            math.dist(s, near[:2]),
        ),
    )


@dataclass(frozen=True)
class PlacedMove(Move):
    """A move onto the table with the table position ``at`` (x, y) the plan chose for it, at
    the planner's table place named ``place`` (None: not planned on places)."""

    at: XY | None = field(default=None, compare=False)
    place: str | None = field(default=None, compare=False)


def plain_move(move: Move, at: Mapping[str, XY], where: XY | None = None) -> Move:
    """A planned move onto a place as a move onto the table at that place (`PlacedMove`):
    at ``where`` when given (the position its window decided), else at the place's centre."""
    if move.target in at:
        xy = at[move.target] if where is None else where
        return PlacedMove(move.entity, TABLE, xy, move.target)
    return move


def place_pose(
    move: Move, poses: Mapping[str, Pose], config: SceneConfig = SceneConfig(), rank: int = 0
) -> Pose | None:
    """Where the moved block's centre should end: on top of the target block, or on a free
    table slot, the ``rank``-th best (None when the table has no more free slots); a move
    that names its table place (``move.at``, `PlacedMove`) tries that first."""
    if move.entity not in poses:
        raise ProblemError(f"unknown block {one_of(move.entity, sorted(poses))}")
    s = config.block_size
    if move.target == TABLE:
        others = {k: v for k, v in poses.items() if k != move.entity}
        slots = free_slots(others, poses[move.entity].xyz, config)
        at = move.at if isinstance(move, PlacedMove) else None
        if at is not None and all(
            math.dist(at, p.xy) > config.slot_radius for p in others.values()
        ):
            slots = [tuple(at), *(k for k in slots if math.dist(k, at) > 1e-6)]
        if rank >= len(slots):
            return None
        return Pose((slots[rank][0], slots[rank][1], s / 2), 0.0)
    if move.target not in poses:
        raise ProblemError(f"unknown target {one_of(move.target, [*sorted(poses), TABLE])}")
    below = poses[move.target]
    return Pose((below.xyz[0], below.xyz[1], below.xyz[2] + s), below.yaw)
