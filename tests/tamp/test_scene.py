"""The scene model: state -> poses -> state round trips, slots, placement targets, errors."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.loop.faults import Injection
from tamp.scene import (
    Pose,
    SceneConfig,
    SceneError,
    colour,
    cube_yaw,
    free_slot,
    layout,
    place_pose,
    towers,
)
from tamp.world.convert.from_poses import read_state
from task.errors import ProblemError, TampError
from task.problem import TABLE, Move

ENTITIES = ("a", "b", "c", "d", "e")


@pytest.mark.parametrize("seed", range(20))
def test_layout_then_read_state_round_trips(seed):
    rng = np.random.default_rng(seed)
    order = list(rng.permutation(ENTITIES))
    state, below = {}, TABLE
    for x in order:  # random towers: each block on the table or on the previous one
        below = TABLE if rng.random() < 0.4 else below
        state[x] = below
        below = x
    crisp = tuple(state[x] for x in ENTITIES)
    poses = layout(ENTITIES, crisp, seed=seed)
    assert read_state(ENTITIES, poses).state == crisp


def test_read_state_names_a_floating_block():
    poses = layout(("a", "b"), (TABLE, TABLE))
    poses["b"] = Pose((0.9, 0.9, 0.2))
    reading = read_state(("a", "b"), poses)
    assert reading.state is None
    assert "block b" in reading.issues[0]


def test_place_pose_on_a_block_and_on_a_free_slot():
    poses = layout(("a", "b"), ("b", TABLE), seed=3)
    on_b = place_pose(Move("a", "b"), poses)
    assert on_b.xyz[2] == pytest.approx(poses["b"].xyz[2] + 0.05)
    to_table = place_pose(Move("a", TABLE), poses)
    assert to_table.xyz[2] == pytest.approx(0.025)
    assert np.linalg.norm(to_table.xy - poses["b"].xy) > SceneConfig().slot_radius


def test_full_table_has_no_free_slot():
    config = SceneConfig(slot_xs=(0.5,), slot_ys=(0.0,))
    poses = {"a": Pose((0.5, 0.0, 0.025))}
    assert free_slot(poses, (0.5, 0.0), config) is None


def test_bad_scene_inputs_are_clear_errors():
    with pytest.raises(ProblemError, match="unknown target"):
        place_pose(Move("a", "zz"), layout(("a",), (TABLE,)))
    with pytest.raises(SceneError, match="11 towers leave no free table slot"):
        layout(tuple("abcdefghijk"), (TABLE,) * 11)
    with pytest.raises(ProblemError, match="cycle"):
        towers(("a", "b"), ("b", "a"))


def test_as_many_towers_as_slots_is_refused_with_a_true_message():
    config = SceneConfig(slot_xs=(0.45, 0.6), slot_ys=(0.0,))  # 2 slots
    assert set(layout(("a", "b"), (TABLE, "a"), config)) == {"a", "b"}  # 1 tower: one slot free
    with pytest.raises(SceneError) as excinfo:
        layout(("a", "b"), (TABLE, TABLE), config)  # 2 towers on 2 slots: none left free
    message = str(excinfo.value)
    assert message.startswith("2 towers leave no free table slot: the scene has 2 slots")
    assert "(at most 1 towers)" in message and "more than" not in message


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (None, Injection()),
        ("drop:0.2", Injection(drop=0.2)),
        ("drop:0.2,nudge:0.1,noise:0.5", Injection(drop=0.2, nudge=0.1, noise=0.5)),
    ],
)
def test_fault_specs_parse(text, expected):
    assert Injection.parse(text) == expected


@pytest.mark.parametrize("text", ["drop", "fall:0.2", "drop:x", "drop:1.5"])
def test_bad_fault_specs_are_clear_errors(text):
    with pytest.raises(TampError):
        Injection.parse(text)


def test_cube_yaw_reads_a_cube_lying_on_its_side():
    def rz(a):
        return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])

    ry90 = np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])  # tipped over about y
    for yaw in (-0.7, -0.2, 0.0, 0.3, 0.7):
        got = cube_yaw(rz(yaw) @ ry90)
        assert abs(np.remainder(got - yaw + np.pi / 4, np.pi / 2) - np.pi / 4) < 1e-9


def test_free_slot_prefers_room_away_from_towers_then_nearness():
    config = SceneConfig(slot_xs=(0.5,), slot_ys=(-0.32, -0.16, 0.0, 0.16, 0.32))
    poses = {"a": Pose((0.5, 0.0, 0.025)), "b": Pose((0.5, 0.0, 0.075))}
    # -0.16 and 0.16 are free and nearest, but right beside the tower
    assert free_slot(poses, (0.5, 0.0), config) in ((0.5, -0.32), (0.5, 0.32))
    assert free_slot(poses, (0.5, 0.3), config) == (0.5, 0.32)


def test_blocks_beyond_the_palette_get_distinct_colours():
    names = tuple(f"b{i}" for i in range(14))
    state = (
        TABLE,
        "b0",
        "b1",
        "b2",
        TABLE,
        "b4",
        "b5",
        "b6",
        TABLE,
        "b8",
        "b9",
        "b10",
        TABLE,
        "b12",
    )
    assert len(layout(names, state)) == 14  # more blocks than the 10 palette colours
    rgbs = [colour(i) for i in range(14)]
    assert len(set(rgbs)) == 14 and all(0.0 <= c <= 1.0 for rgb in rgbs for c in rgb)
