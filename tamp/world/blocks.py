"""A scene file as a Blocksworld episode: what ``tamp run --scene FILE --goal GOAL`` runs.

`scene_task` loads the scene, reads its symbolic state from the geometry (`read_facts`), and
builds the Blocksworld `task.problem.Problem` the closed loop plans for: the movable objects are
the entities, the supports read from their poses the initial state, the goal's ``on`` and
``ontable`` atoms the goal. The episode starts from the file's object poses, among its
obstacles (and its regions' walls and floors), on its slot grid (`scene_config`), with each
object's colour.

A scene the geometry cannot explain is one `SceneFileError` line, before any work. What is
beyond the Blocksworld loop is a `BeyondLoop` (a `SceneFileError`) instead: an object that is not
a cube of the loop's block size, an object resting in a region, a scene where nothing may be
parked on the bare table, a goal atom other than ``on`` / ``ontable`` (``in``: regions are not
the loop's targets), and poses from which the loop's state reader reads no Blocksworld state.
The initial state is what the loop reads at every observation
(`tamp.world.convert.from_poses.read_state`: the same reader, `read_facts`, at the loop's
tolerances), so the loop plans from the state it then observes. ``tamp run`` runs a scene
beyond the loop through the geometric TAMP episode (`tamp.geo.episode`) instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tamp.scene import Pose, SceneConfig
from tamp.world.convert.from_poses import read_state
from tamp.world.goal import Goal, load_goal
from tamp.world.goal_check import check_goal
from tamp.world.load import load_scene, scene_config
from tamp.world.relations import Facts, read_facts
from tamp.world.schema import Scene, SceneFileError
from task.problem import TABLE, Problem

GOAL_PREDICATES = ("on", "ontable")  # what a Blocksworld goal names: supports


class BeyondLoop(SceneFileError):
    """A well-formed scene file, or its goal, that the Blocksworld loop cannot run (regions,
    shapes, parking rules): the geometric episode can."""


@dataclass(frozen=True)
class SceneTask:
    """A scene file and its goal, ready for `tamp.loop.Episode`: the ``problem`` (its init read
    from the geometry), the objects' ``poses`` (entity order) and the ``config`` of the table."""

    scene: Scene
    goal: Goal
    facts: Facts
    problem: Problem
    poses: tuple[tuple[str, Pose], ...]
    config: SceneConfig


def scene_task(
    path: str | Path | Scene, goal: str | Path, base: SceneConfig = SceneConfig()
) -> SceneTask:
    """The Blocksworld episode of the scene file at ``path`` (or a loaded `Scene`) and the goal
    ``goal`` (inline PDDL or a file, `load_goal`), on ``base``'s block size; SceneFileError,
    one line, when the loop cannot run it (see the module docstring)."""
    scene, facts = explained_scene(path)
    label = scene.name if isinstance(path, Scene) else str(path)
    _check_blocks(scene, base.block_size, label)
    if not scene.parking:
        raise BeyondLoop(
            f"{label}: parking: false: the loop parks blocks on the bare table, which this "
            "scene forbids"
        )
    in_regions = [f"{x} in {s}" for x, s in facts.supports if s in {r.name for r in scene.regions}]
    if in_regions:
        raise BeyondLoop(
            f"{label}: {', '.join(in_regions)}: objects in regions are beyond the Blocksworld "
            "loop (its supports are the table and blocks)"
        )
    wanted = check_goal(scene, load_goal(goal, scene))  # unsolvable: before any planning
    for atom in wanted.atoms:
        if atom[0] not in GOAL_PREDICATES:
            why = (
                "regions are the geometric episode's targets"
                if atom[0] == "in"
                else "a Blocksworld goal names supports"
            )
            raise BeyondLoop(
                f"goal: ({' '.join(atom)}): the loop plans goals of "
                f"{' and '.join(GOAL_PREDICATES)} atoms only ({why})"
            )
    entities = tuple(o.name for o in scene.objects)
    config = scene_config(scene, base)  # obstacles, walls, floors, slots, bodies, colours
    poses = tuple((o.name, o.pose) for o in scene.objects)
    problem = Problem(
        name=scene.name,
        domain="blocksworld",
        entities=entities,
        init=_loop_state(entities, dict(poses), config, label),
        goal=tuple((a[1], a[2] if a[0] == "on" else TABLE) for a in wanted.atoms),
    )
    return SceneTask(scene, wanted, facts, problem, poses, config)


def explained_scene(path: str | Path | Scene) -> tuple[Scene, Facts]:
    """The scene file at ``path`` (or a loaded `Scene`, as it is) and the facts read from its
    geometry; SceneFileError when it has no movable object or the geometry cannot explain one
    (any episode needs both)."""
    scene = path if isinstance(path, Scene) else load_scene(path)
    if isinstance(path, Scene):
        path = scene.name  # what the messages name
    if not scene.objects:
        raise SceneFileError(f"{path}: objects: the scene has no movable object to plan for")
    facts = read_facts(scene)
    if facts.unexplained:
        raise SceneFileError(
            f"{path}: the geometry cannot explain object(s) {', '.join(facts.unexplained)}: "
            + "; ".join(facts.issues)
        )
    return scene, facts


def _check_blocks(scene: Scene, size: float, label: str) -> None:
    for i, o in enumerate(scene.objects):
        if o.kind != "cube" or abs(o.size[0] - size) > 1e-9:
            shape = o.kind if o.kind == "cube" else f"a {o.kind}"
            raise BeyondLoop(
                f"{label}: objects[{i}] ({o.name}): {shape} of size "
                f"{', '.join(f'{v:g}' for v in o.size)} m; the loop moves cubes of "
                f"{size:g} m only (yet)"
            )


def _loop_state(entities: tuple[str, ...], poses: dict, config: SceneConfig, label: str):
    """The initial state as the loop reads it at every observation (`read_state`, the one scene
    reader at the loop's tolerances, on the loop's table): BeyondLoop when it reads none."""
    reading = read_state(entities, poses, config)
    if reading.state is None:
        raise BeyondLoop(
            f"{label}: the loop's state reader (bottoms within {config.tol_z * 1000:.0f} mm of "
            f"a face, a block on another only with its centre over it) reads no Blocksworld "
            f"state from the poses: {'; '.join(reading.issues)}"
        )
    return reading.state
