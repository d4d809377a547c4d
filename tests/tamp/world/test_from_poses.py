"""The loop's state reader (`tamp.world.convert.from_poses.read_state`) is the support projection
of the one scene reader, `read_facts`, on the loop's world seen as a scene, at the loop's
tolerances."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.obstacles import Obstacle
from tamp.scene import Body, Pose, SceneConfig, SceneError, layout
from tamp.world.convert.from_poses import loop_scene, read_state
from tamp.world.geometry import LOOP, TIGHT, loop_tolerances
from tamp.world.relations import read_facts
from task.problem import TABLE

ENTITIES = ("a", "b", "c", "d", "e")


def on_a(dx: float, dy: float, dz: float = 0.0) -> dict[str, Pose]:
    """Block b on block a, off its centre by (dx, dy) and ``dz`` above a's top."""
    return {"a": Pose((0.5, 0.0, 0.025)), "b": Pose((0.5 + dx, dy, 0.075 + dz))}


@pytest.mark.parametrize("seed", range(10))
def test_the_state_is_the_support_projection_of_the_facts(seed):
    rng = np.random.default_rng(seed)
    state, below = {}, TABLE
    for x in rng.permutation(ENTITIES):
        below = TABLE if rng.random() < 0.4 else below
        state[str(x)] = below
        below = str(x)
    crisp = tuple(state[x] for x in ENTITIES)
    poses = layout(ENTITIES, crisp, seed=seed)
    facts = read_facts(loop_scene(ENTITIES, poses, SceneConfig()), LOOP)
    assert read_state(ENTITIES, poses).state == crisp
    assert tuple(dict(facts.supports)[x] for x in ENTITIES) == crisp


@pytest.mark.parametrize(
    ("offset", "expected"),
    [
        ((0.0, 0.022, 0.0), ("table", "a")),  # centre over a: rests on it (the old 20 mm: loose)
        ((0.015, 0.015, 0.0), ("table", "a")),  # 21 mm on the diagonal, still over a
        ((0.0, 0.0, 0.011), ("table", "a")),  # within the loop's 12 mm of a's top
        ((0.0, 0.03, 0.0), None),  # centre past a's edge: it tips, on neither
        ((0.0, 0.0, 0.014), None),  # floats
    ],
)
def test_a_block_rests_on_another_when_its_centre_is_over_it(offset, expected):
    assert read_state(("a", "b"), on_a(*offset)).state == expected


def test_the_loops_tolerances_are_the_scene_configs_and_looser_than_a_files():
    config = SceneConfig()
    assert loop_tolerances(config) == LOOP and LOOP.z == config.tol_z > TIGHT.z
    assert TIGHT.centre is None and LOOP.centre == 0.0
    # a file's reader takes any footprint overlap; the loop's the support under the centre
    scene = loop_scene(("a", "b"), on_a(0.0, 0.03), config)
    assert dict(read_facts(scene, TIGHT).supports) == {"a": TABLE, "b": "a"}
    assert read_facts(scene, LOOP).unexplained == ("b",)


def test_unreadable_states_name_the_block_and_the_reason():
    across = {
        "a": Pose((0.5, 0.0, 0.025)),
        "b": Pose((0.5, 0.05, 0.025)),
        "c": Pose((0.5, 0.025, 0.075)),  # across a and b, its centre over both edges
    }
    reading = read_state(("a", "b", "c"), across)
    assert reading.state is None and reading.loose == ("c",)
    assert "block c at (0.500, 0.025, 0.075) rests on neither" in reading.issues[0]
    post = Obstacle("post", (0.5, 0.0, 0.05), (0.03, 0.03, 0.05))
    config = SceneConfig(obstacles=(post,))
    on_post = read_state(("a",), {"a": Pose((0.5, 0.0, 0.125))}, config)
    assert on_post.state is None and on_post.loose == ("a",)
    two = {"a": Pose((0.5, 0.0, 0.025)), "b": Pose((0.5, 0.0, 0.075)), "c": Pose((0.5, 0, 0.075))}
    assert read_state(("a", "b", "c"), two).issues == ("blocks b and c both rest on a",)
    with pytest.raises(SceneError, match=r"no pose for blocks \['b'\]"):
        read_state(("a", "b"), {"a": Pose((0.5, 0.0, 0.025))})


def test_each_block_is_its_own_solid_and_the_table_is_a_plane():
    box = Body("cuboid", (0.04, 0.02, 0.04))
    config = SceneConfig(bodies=(("box", box),))
    poses = {"box": Pose((0.5, 0.0, 0.04), 0.3), "a": Pose((0.5, 0.0, 0.105))}
    assert read_state(("box", "a"), poses, config).state == (TABLE, "box")
    far = {"a": Pose((1.4, 0.9, 0.025))}  # beyond the named scenes' table top: still the table
    assert read_state(("a",), far).state == (TABLE,)
