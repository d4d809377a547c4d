"""A Blocksworld PDDL problem laid out as a scene: the scene generator of the loop's table.

`problem_scene` turns a `task.problem.Problem` of the ``blocksworld`` domain into a
`tamp.world.Scene` and a `tamp.world.Goal`, laid out exactly as the closed loop lays the problem
out (`tamp.loop.Episode`, `tamp.scene.layout` with the same seed): the blocks are cubes of the
workcell's block size on its table slots, jittered in xy and yaw, stacked as the problem's
initial state says, each in the colour the loop gives it; the workcell (one of the shipped
scenes ``tabletop``, ``shelf``, ``clutter``, ``cramped``, `tamp.world.load_named`) gives the
table, the slot grid and the fixed obstacles. The goal's ``(entity, support)`` atoms become
``(on x y)`` and ``(ontable x)``.

The scene is checked as any scene file is (`tamp.world.load.load_scene`), so what cannot be a
scene (a name the schema refuses, too many towers for the slots) is one `TampError` line. Read
back with `tamp.world.read_facts`, its ``on`` / ``ontable`` / ``clear`` facts are the problem's
initial state: the Blocksworld state is the support projection of the scene's.
"""

from __future__ import annotations

from dataclasses import dataclass

from tamp.scene import SceneConfig, colour, layout
from tamp.world.goal import Goal
from tamp.world.load import load_named, load_scene, scene_config, scene_dict
from tamp.world.relations import Atom
from tamp.world.schema import Movable, Scene, SceneFileError
from task.errors import TampError
from task.problem import TABLE, Problem

DOMAIN = "blocksworld"  # the domain whose problems lay out as blocks on the table


@dataclass(frozen=True)
class ProblemScene:
    """A Blocksworld problem as a scene: the ``scene`` (its name the problem's), the
    ``goal`` over its objects, and the ``workcell`` and ``seed`` it was laid out with."""

    scene: Scene
    goal: Goal
    workcell: str
    seed: int


def problem_scene(
    problem: Problem, workcell: str = "tabletop", seed: int = 0, base: SceneConfig = SceneConfig()
) -> ProblemScene:
    """``problem`` laid out on the named ``workcell`` with ``seed``, as the loop lays it out
    with ``base``'s blocks (see the module docstring); one TampError line for a problem of
    another domain or one the workcell cannot hold."""
    if problem.domain != DOMAIN:
        raise TampError(
            f"{problem.name}: only {DOMAIN} problems lay out as blocks on the table; this is a "
            f"{problem.domain} problem"
        )
    room = load_named(workcell)
    config = scene_config(room, base)  # the loop's table: `tamp.world.load_named` + this
    poses = layout(problem.entities, problem.init, config, seed)
    size = config.block_size
    objects = tuple(
        Movable(x, "cube", (size,), colour(i, config.palette), poses[x])
        for i, x in enumerate(problem.entities)
    )
    laid = Scene(
        name=problem.name,
        table=room.table,
        obstacles=room.obstacles,
        objects=objects,
        slots=room.slots,
    )
    scene = _checked(laid, f"{problem.name} on workcell {workcell} (seed {seed})")
    return ProblemScene(scene, Goal(goal_atoms(problem)), workcell, seed)


def goal_atoms(problem: Problem) -> tuple[Atom, ...]:
    """The problem's goal as scene atoms: ``(x, table)`` -> ``(ontable x)``, ``(x, y)`` ->
    ``(on x y)``."""
    return tuple(("ontable", x) if y == TABLE else ("on", x, y) for x, y in problem.goal)


def _checked(scene: Scene, where: str) -> Scene:
    """``scene`` through the scene file's checks (`load_scene` of its dict): a fault is one
    line naming ``where`` it comes from."""
    try:
        return load_scene(scene_dict(scene))
    except SceneFileError as exc:
        raise SceneFileError(f"{where}: {str(exc).removeprefix('scene: ')}") from None
