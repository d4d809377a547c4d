"""``tamp bench checker`` (`tamp.bench.collision`): scenes, samples and a tiny run end to end."""

from __future__ import annotations

import csv
import json
import sys

import numpy as np
import pytest

from motion.sphere_check import SphereCollision
from tamp.bench.collision import scenes
from tamp.cli import main
from tamp.obstacles import SCENES


def test_scene_boxes_are_the_obstacles_and_seeded_towers_under_the_shelf():
    boxes = scenes.scene_boxes("shelf", seed=3)
    assert boxes == scenes.scene_boxes("shelf", seed=3)
    names = [b.name for b in boxes]
    assert names[: len(SCENES["shelf"])] == [o.name for o in SCENES["shelf"]]
    blocks = boxes[len(SCENES["shelf"]) :]
    assert blocks and len(names) == len(set(names))
    board = SCENES["shelf"][0]
    for b in blocks:  # every block stays under the board with room for the hand
        assert b.centre[2] + b.half[2] < board.bottom


def test_the_near_sample_is_flagged_by_the_wide_model_and_seeded():
    boxes = scenes.scene_boxes("clutter", seed=0)
    q = scenes.near(boxes, 200, seed=1, margin=0.01)
    assert q.shape == (200, 7)
    assert np.array_equal(q, scenes.near(boxes, 200, seed=1, margin=0.01))
    wide = SphereCollision(margin=0.01 + scenes.NEAR_MARGIN)
    wide.set_boxes(boxes)
    assert not wide.valid_batch(q).any()


@pytest.mark.sim
def test_a_tiny_run_writes_its_tables_and_finds_no_false_free(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["bench", "checker", "--scenes", "cramped", "--batch", "20,50", "--repeats", "1"]
    argv += ["--near", "40", "--moves", "1", "--seed", "2", "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "configs/s" in printed and "false free" in printed and "ompl_mesh" in printed
    body = json.loads((out / "results.json").read_text())
    assert body["config"]["scenes"] == ["cramped"] and body["config"]["seed"] == 2
    assert body["machine"]["command"].startswith("tamp bench checker")
    (scene,) = body["scenes"]
    assert scene["validation"]["n"] == 40 and scene["validation"]["false_free"] == 0
    assert [r["batch"] for r in scene["throughput"]] == [20, 50, 20, 50]
    for row in scene["throughput"]:  # both rates, and the one thread that worked
        assert row["configs_per_s"] > 0 and row["configs_per_cpu_s"] > 0
        assert row["threads"] == (1 if sys.platform.startswith("linux") else None)
    with (out / "moves.csv").open() as f:
        moves = list(csv.DictReader(f))
    assert [m["planner"] for m in moves] == ["spheres", "ompl_mesh"]
    with (out / "throughput.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 4 and "threads" in rows[0]


def test_an_unknown_scene_is_refused_in_one_line(capsys):
    assert main(["bench", "checker", "--scenes", "shelf,garden"]) == 2
    err = capsys.readouterr().err.strip()
    assert "garden" in err and "cramped" in err and len(err.splitlines()) == 1
