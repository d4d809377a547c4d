"""tamp.world: scenes as input. A scene file describes the table, its regions, fixed obstacles
and movable objects; the symbolic state is read from that geometry, never given.

- ``tamp.world.schema``: the versioned JSON schema (documented field by field) and the frozen
  dataclasses a file parses into (`Scene`, `Table`, `Region`, `Movable`, `Slots`; obstacles are
  `tamp.obstacles.Obstacle`);
- ``tamp.world.load``: `load_scene` (a path or a dict -> a checked `Scene`, or one
  `SceneFileError` line naming the field and the problem), `scene_dict` / `save_scene`, and
  the shipped scenes (`load_named`: ``tabletop``, ``shelf``, ``clutter``, ``cramped`` and
  examples, in ``tamp/world/scenes/*.json``);
- ``tamp.world.geometry``: upright solids, overlaps and what each object rests on;
- ``tamp.world.relations``: `read_facts`, the ``on`` / ``in`` / ``ontable`` / ``clear`` facts
  read from the poses, and the objects the geometry cannot explain;
- ``tamp.world.goal``: `load_goal` / `parse_goal`, a PDDL goal over the scene's objects and
  regions, checked against the scene;
- ``tamp.world.goal_check``: `check_goal`, the static check of a goal no plan can reach (two
  supports, two objects on one, a cycle, an object a region cannot hold, regions that do not
  nest), run before any planning: ``tamp run`` reports ``unsolvable: REASON`` at once.
- ``tamp.world.scene_pddl``: `problem_text`, a scene and a goal as the PDDL problem of a
  user's pick-and-place domain, its state read from the geometry through the binding's scene
  section (``tamp run --scene FILE --domain D.pddl --binding B.json``);
- ``tamp.world.blocks``: `scene_task`, a scene file and a goal as the closed loop's Blocksworld
  episode (``tamp run --scene FILE.json --goal GOAL``), or one line saying what it cannot run;
- ``tamp.world.convert``: scenes made from the other world models: `problem_scene`
  (``convert.from_problem``), the other way from `scene_task`: a Blocksworld PDDL problem laid
  out as a scene on a named workcell (the loop's slots and seed), with its goal, so any
  geometric planner runs it (``tamp run PROBLEM.pddl --geo-planner P``); and
  ``convert.workcells``, the named workcells of `tamp.obstacles` written as scene files.

World frame = the robot base frame (``panda_link0``), the table surface at z = 0, metres and
radians, as in `tamp.scene`.
"""

from tamp.world.geometry import Tolerances
from tamp.world.goal import Goal, load_goal, parse_goal
from tamp.world.load import (
    load_named,
    load_scene,
    named_scenes,
    save_scene,
    scene_config,
    scene_dict,
)
from tamp.world.relations import Facts, read_facts
from tamp.world.schema import SCHEMA, Movable, Region, Scene, SceneFileError, Slots, Table

__all__ = [
    "SCHEMA",
    "Facts",
    "Goal",
    "Movable",
    "Region",
    "Scene",
    "SceneFileError",
    "Slots",
    "Table",
    "Tolerances",
    "load_goal",
    "load_named",
    "load_scene",
    "named_scenes",
    "parse_goal",
    "read_facts",
    "save_scene",
    "scene_config",
    "scene_dict",
]
