"""The loop's world as a scene, and its Blocksworld state: the support projection of the one
scene reader.

The closed loop observes block poses on its table (`tamp.scene.SceneConfig`). `loop_scene` sees
them as the `tamp.world.schema.Scene` they form (each block its own solid, the table's fixed
boxes as obstacles, its slot grid), and `read_state` reads that scene with `read_facts`, the
reader of every scene, at the loop's tolerances (`tamp.world.geometry.loop_tolerances`). The
Blocksworld state is the facts' supports in entity order: each block on the table or on one
block. A block the facts leave unexplained (floating, on an obstacle's top, across two blocks,
tipped past its support's edge) or two blocks on one block make the state unreadable: a
`Reading` with no state and one line per reason.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from tamp.scene import Pose, SceneConfig, SceneError, colour
from tamp.world.geometry import loop_tolerances
from tamp.world.relations import read_facts
from tamp.world.schema import Movable, Scene, Slots, Table
from task.problem import TABLE

# the named scenes' table top (`tamp/world/scenes/*.json`), m: (x, y) low and high corners
TABLE_LO, TABLE_HI = (-0.3, -0.7), (1.0, 0.7)


@dataclass(frozen=True)
class Reading:
    """The state read from poses: supports in entity order, or None with the reasons."""

    state: tuple[str, ...] | None
    issues: tuple[str, ...] = ()
    loose: tuple[str, ...] = ()  # blocks resting on neither the table nor one block


def loop_scene(entities: Sequence[str], poses: Mapping[str, Pose], config: SceneConfig) -> Scene:
    """The blocks ``entities`` at ``poses`` on ``config``'s table as a scene: each block its
    solid (`SceneConfig.body`) in the loop's colour, the table's fixed boxes as obstacles (its
    marks, drawn only, are no solids), its slot grid. The table top is the named scenes',
    grown to hold every block: the simulators' table is a plane."""
    missing = [x for x in entities if x not in poses]
    if missing:
        raise SceneError(f"no pose for blocks {missing} (poses given: {sorted(poses)})")
    objects = tuple(
        _movable(x, poses[x], config, colour(i, config.palette)) for i, x in enumerate(entities)
    )
    xs = [TABLE_LO[0], TABLE_HI[0], *(float(poses[x].xyz[0]) for x in entities)]
    ys = [TABLE_LO[1], TABLE_HI[1], *(float(poses[x].xyz[1]) for x in entities)]
    return Scene(
        config.name,
        Table((min(xs), min(ys)), (max(xs), max(ys))),
        obstacles=tuple(config.obstacles),
        objects=objects,
        slots=Slots(tuple(config.slot_xs), tuple(config.slot_ys)),
    )


def _movable(name: str, pose: Pose, config: SceneConfig, rgb) -> Movable:
    """Block ``name`` at ``pose`` as a scene object of its solid (`SceneConfig.body`)."""
    body = config.body(name)
    hx, hy, hz = body.half
    sizes = {"cube": (2 * hx,), "cylinder": (2 * hx, 2 * hz), "cuboid": (2 * hx, 2 * hy, 2 * hz)}
    size = sizes[body.kind]  # as a scene file gives it (`tamp.world.schema.Movable.size`)
    xyz = tuple(float(v) for v in pose.xyz)
    return Movable(name, body.kind, size, tuple(rgb), Pose(xyz, float(pose.yaw)))


def read_state(
    entities: Sequence[str], poses: Mapping[str, Pose], config: SceneConfig = SceneConfig()
) -> Reading:
    """Observed poses -> crisp supports: `loop_scene` read by `read_facts` at
    `loop_tolerances` (a block rests on a face when its bottom lies within ``config.tol_z`` of
    it, on a block only with its centre over that block), the supports in ``entities`` order
    (see the module docstring). SceneError when a block has no pose."""
    facts = read_facts(loop_scene(entities, poses, config), loop_tolerances(config))
    support = dict(facts.supports)
    issues, loose = [], []
    for x in entities:
        if x not in support:
            where = ", ".join(f"{v:.3f}" for v in poses[x].xyz)
            issues.append(f"block {x} at ({where}) rests on neither the table nor one block")
            loose.append(x)
    onto: dict[str, str] = {}
    for x in entities:
        below = support.get(x, TABLE)
        if below != TABLE and below in onto:
            issues.append(f"blocks {onto[below]} and {x} both rest on {below}")
        onto[below] = x
    if issues:
        return Reading(None, tuple(issues), tuple(loose))
    return Reading(tuple(support[x] for x in entities))
