"""A scene file as a Blocksworld episode (`tamp.world.blocks.scene_task`): the initial state is
read from the geometry, and what the loop cannot run yet is one `SceneFileError` line."""

from __future__ import annotations

import json

import pytest

from tamp.geo.scene_file import scene_episode
from tamp.world import SceneFileError, load_named
from tamp.world.blocks import SceneTask, scene_task
from tamp.world.load import SCENES_DIR
from tests.tamp.world.test_load import TRAY, cube, scene

POST = {"name": "post", "centre": [0.4, -0.2, 0.05], "half": [0.03, 0.03, 0.05]}


def write(tmp_path, data, name="s.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def test_a_tower_in_the_file_is_read_as_a_tower(tmp_path):
    path = write(
        tmp_path,
        scene(
            cube("a", 0.4, -0.16, 0.075), cube("b", 0.4, -0.16, 0.025), cube("c", 0.4, 0.16, 0.025)
        ),
    )
    task = scene_task(path, "(and (on b c) (ontable a))")
    assert task.problem.entities == ("a", "b", "c")
    assert task.problem.init == ("b", "table", "table")
    assert task.problem.goal == (("b", "c"), ("a", "table"))
    assert dict(task.poses)["a"].xyz == (0.4, -0.16, 0.075)
    assert [name for name, _ in task.config.palette] == ["a", "b", "c"]


def test_the_goal_may_be_a_file_and_the_shipped_example_is_a_tower(tmp_path):
    goal = tmp_path / "goal.pddl"
    goal.write_text("(define (problem p) (:domain blocksworld) (:goal (and (on c a))))")
    task = scene_task(SCENES_DIR / "tower.json", goal)
    assert task.problem.init == ("b", "table", "table")
    assert task.problem.goal == (("c", "a"),)
    assert task.scene == load_named("tower")


def test_the_scene_s_obstacles_slots_and_region_walls_are_the_table(tmp_path):
    data = scene(cube("a", 0.4, 0.0, 0.025), regions=[TRAY], obstacles=[POST])
    data["slots"] = {"xs": [0.4, 0.5], "ys": [0.0, -0.3]}
    task = scene_task(write(tmp_path, data), "(ontable a)")
    names = [o.name for o in task.config.obstacles]
    assert names[0] == "post" and "tray:wall_x0" in names
    assert task.config.slot_xs == (0.4, 0.5) and task.config.slot_ys == (0.0, -0.3)


@pytest.mark.parametrize(
    ("objects", "goal", "expected"),
    [
        (  # a cube on an obstacle's top
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.4, -0.2, 0.125)],
            "(on a b)",
            "cannot explain object(s) b: object b rests on post",
        ),
        (  # a cube bridging two
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.5, 0.05, 0.025), cube("c", 0.5, 0.025, 0.075)],
            "(on a b)",
            "cannot explain object(s) c",
        ),
        ([cube("a", 0.5, 0.0, 0.03, size=0.06)], "(ontable a)", "cube of size 0.06 m"),
        (
            [
                {
                    "name": "a",
                    "kind": "cylinder",
                    "size": [0.05, 0.05],
                    "colour": "red",
                    "pose": {"xyz": [0.5, 0.0, 0.025]},
                }
            ],
            "(ontable a)",
            "a cylinder of size 0.05, 0.05 m; the loop moves cubes of 0.05 m",
        ),
        ([cube("a", 0.5, 0.0, 0.025)], "(in a tray)", "regions are the geometric episode's"),
        ([cube("a", 0.5, 0.0, 0.025)], "(clear a)", "on and ontable atoms only"),
        ([cube("a", 0.55, 0.25, 0.025)], "(ontable a)", "a in tray: objects in regions are beyond"),
        ([], "(on a b)", "no movable object"),
        ([cube("a", 0.5, 0.0, 0.025)], "(on a zz)", "unknown object 'zz'"),
    ],
)
def test_what_the_loop_cannot_run_is_one_line(tmp_path, objects, goal, expected):
    path = write(tmp_path, scene(*objects, regions=[TRAY], obstacles=[POST]))
    with pytest.raises(SceneFileError) as info:
        scene_task(path, goal)
    assert expected in str(info.value) and "\n" not in str(info.value), str(info.value)


@pytest.mark.parametrize(
    "offset",
    [(0.0, 0.022), (0.016, 0.016), (-0.023, 0.0)],  # off the old 20 mm, centre still over a
)
def test_a_block_off_centre_on_another_reads_one_state_and_runs_in_the_loop(tmp_path, offset):
    """The file's facts and the loop's reading are one reader's: a block whose centre is over
    the block below rests on it (once a BeyondLoop: the loop's own reader wanted 20 mm)."""
    dx, dy = offset
    path = write(tmp_path, scene(cube("a", 0.5, 0.0, 0.025), cube("b", 0.5 + dx, dy, 0.075)))
    task = scene_episode(str(path), "(ontable b)")
    assert isinstance(task, SceneTask)
    assert task.problem.init == ("table", "a") == tuple(s for _, s in task.facts.supports)
