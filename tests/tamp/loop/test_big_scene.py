"""A scene file of hundreds of cubes whose goal needs a few moves: ``tamp run`` plans it as
``tamp plan`` plans the same problem, with Blocksworld's planner defaults for big problems
(constructive moves without a window, windows over the part they reach), not one soft window
over every block (at 300 cubes: 40 s a window, 180 s and more before the first move)."""

from __future__ import annotations

import json
import math
import random

import pytest

from tamp.cli import build_parser
from tamp.cli.recorded import loop_config, scene_run
from tamp.loop import LoopConfig
from tamp.world import geometry
from tamp.world.geometry import Solid, apart, footprint_gap
from tamp.world.load import MAX_REACH, MIN_REACH, load_scene
from task.config import PlannerConfig
from task.planner import plan

GOAL = "(and (on t0l2 t1l2) (on t2l2 t3l2) (on t4l2 t5l2))"  # three tops onto three tops


def towers(count: int, spacing: float = 0.1, size: float = 0.05) -> dict:
    """A scene dict of ``count`` towers of 3 cubes (``t<k>l<level>``, level 0 on the table) on a
    grid of ``spacing`` m within the arm's reach (`MIN_REACH`..`MAX_REACH` from the base's
    axis, a cube's width inside either bound)."""
    spots = []
    for i in range(-int(MAX_REACH / spacing), int(MAX_REACH / spacing) + 1):
        for j in range(-int(MAX_REACH / spacing), int(MAX_REACH / spacing) + 1):
            x, y = round(i * spacing, 4), round(j * spacing, 4)
            if MIN_REACH + size <= math.hypot(x, y) <= MAX_REACH - size and x >= -0.25:
                spots.append((x, y))
    assert len(spots) >= count, f"{len(spots)} places for {count} towers"
    objects = [
        {
            "name": f"t{k}l{level}",
            "kind": "cube",
            "size": size,
            "colour": "red",
            "pose": {"xyz": [x, y, size / 2 + size * level], "yaw": 0.0},
        }
        for k, (x, y) in enumerate(spots[:count])
        for level in range(3)
    ]
    table = {"min": [-0.3, -0.8], "max": [1.0, 0.8]}
    return {"schema": 1, "name": f"towers-{count}", "table": table, "objects": objects}


def test_the_loop_plans_with_blocksworld_defaults():
    assert LoopConfig().planner == PlannerConfig.for_domain("blocksworld")


def test_a_scene_of_300_cubes_plans_a_3_move_goal_without_a_window(tmp_path):
    path = tmp_path / "towers.json"
    path.write_text(json.dumps(towers(100)))
    args = build_parser().parse_args(["run", "--scene", str(path), "--goal", GOAL])
    task = scene_run(args)
    assert task.problem.n == 300
    config = loop_config(args, task)
    result = plan(task.problem, config.planner, seed=0)  # what the episode's first plan runs
    assert result.solved and len(result.plan) == 3
    assert result.stats["windows"] == 0  # Blocksworld's constructive moves, no soft window


def test_loading_300_cubes_tests_footprints_only_where_they_may_touch(tmp_path, monkeypatch):
    """The loader's pairwise checks (overlap, support) skip pairs apart in height or whose
    footprints' circles do not meet: at 300 cubes 45k pairs, of which few need a footprint
    test (each scene file was read in seconds, and the loop read it four times)."""
    path = tmp_path / "towers.json"
    path.write_text(json.dumps(towers(100)))
    calls = []
    real = geometry.footprint_gap

    def counted(a, b):
        calls.append(1)
        return real(a, b)

    monkeypatch.setattr(geometry, "footprint_gap", counted)
    assert len(load_scene(path).objects) == 300
    assert 0 < len(calls) < 10 * 300


@pytest.mark.parametrize("seed", range(5))
def test_footprints_apart_never_touch(seed):
    """`apart` is conservative: whenever it holds, the footprints' gap is positive."""
    rng = random.Random(seed)

    def solid() -> Solid:
        half = (rng.uniform(0.01, 0.1), rng.uniform(0.01, 0.1), 0.05)
        cylinder = rng.random() < 0.3
        half = (half[0], half[0], half[2]) if cylinder else half
        centre = (rng.uniform(0, 0.4), rng.uniform(0, 0.4), 0.05)
        return Solid("s", cylinder, centre, half, rng.uniform(-math.pi, math.pi))

    pairs = [(solid(), solid()) for _ in range(2000)]
    held = [(a, b) for a, b in pairs if apart(a, b)]
    assert held and len(held) < len(pairs)  # both cases occur
    assert all(footprint_gap(a, b) > 0 for a, b in held)
