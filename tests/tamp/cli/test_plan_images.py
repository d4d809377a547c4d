"""``tamp plan-images INIT GOAL`` through ``main(argv)``: plans from PyBullet renders of cube
scenes that the shipped checkpoint reads, checked by ``tamp validate`` against the PDDL of the
true states (blocks named by colour), and every bad input gives one error line and exit code 2.
"""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from tamp.cli import main
from tamp.cli.images import LATPLAN_CHECKPOINT
from tamp.scene import PALETTE
from task import data
from task.domains.blocksworld_pddl import to_pddl
from task.problem import TABLE, Problem
from tests.cli_check import one_line_error

COLOURS = (4, 5, 0)  # green, purple, red: not the first palette colours
NAMES = tuple(PALETTE[c][0] for c in COLOURS)
INIT = (TABLE, NAMES[0], TABLE)  # purple on green, red alone
GOAL = (NAMES[2], TABLE, NAMES[1])  # green on red, red on purple


def _save(path, rgb: np.ndarray) -> str:
    cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    return str(path)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    """PNG paths: the initial and goal scenes, an RGBA copy of the initial one, and a goal
    scene without the red block."""
    from tamp.camera.render import StateRenderer

    root = tmp_path_factory.mktemp("images")
    with StateRenderer("pybullet") as r:
        init = r.render(NAMES, INIT, seed=1, colours=COLOURS)
        goal = r.render(NAMES, GOAL, seed=2, colours=COLOURS)
        two = r.render(NAMES[:2], (TABLE, NAMES[0]), seed=3, colours=COLOURS[:2])
    rgba = np.dstack([cv2.cvtColor(init, cv2.COLOR_RGB2BGR), np.full(init.shape[:2], 255)])
    cv2.imwrite(str(root / "init_rgba.png"), rgba.astype(np.uint8))
    return {
        "init": _save(root / "init.png", init),
        "goal": _save(root / "goal.png", goal),
        "rgba": str(root / "init_rgba.png"),
        "two": _save(root / "two.png", two),
        "root": root,
    }


@pytest.mark.sim
def test_plan_from_images_validates_against_the_true_states(scenes, capsys):
    out = scenes["root"] / "plan.txt"
    args = ["plan-images", scenes["rgba"], scenes["goal"], "--out", str(out), "--threads", "1"]
    assert main(args) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[-1].startswith("VALID: valid plan of ") and "frozen perception" in printed[-1]
    plan = out.read_text()
    assert plan.splitlines() == printed[:-1]
    assert {"(stack green red)", "(stack red purple)"} <= set(plan.splitlines())
    true = Problem("true", "blocksworld", NAMES, INIT, tuple(zip(NAMES, GOAL, strict=True)))
    (scenes["root"] / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    (scenes["root"] / "true.pddl").write_text(to_pddl(true))
    files = [str(scenes["root"] / name) for name in ("domain.pddl", "true.pddl", "plan.txt")]
    assert main(["validate", *files]) == 0, capsys.readouterr().out


@pytest.mark.sim
def test_json_record_of_optimised_perception_over_several_windows(scenes, capsys):
    args = [
        "plan-images",
        scenes["init"],
        scenes["goal"],
        "--perception",
        "optimised",
        "--horizon",
        "1",
        "--lookahead-share",
        "0",
        "--threads",
        "1",
        "--json",
    ]
    assert main(args) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["blocks"] == ["red", "green", "purple"]  # palette order
    assert record["valid"] and record["status"] == "solved"
    assert record["perceived_init"] == dict(zip(NAMES, INIT, strict=True))
    assert record["perceived_goal"] == dict(zip(NAMES, GOAL, strict=True))
    assert record["stats"]["windows"] >= 2  # windows after the first start from unseen states
    assert len(record["actions"]) == 2 * len(record["moves"]) == record["validation"]["length"]
    assert record["perception"] == "optimised" and record["config"]["horizon"] == 1
    assert set(record["timing"]) == {"read_s", "perception_s", "planning_s", "total_s"}


@pytest.mark.sim
def test_a_block_missing_from_one_image_is_named(scenes, capsys):
    assert main(["plan-images", scenes["init"], scenes["two"]]) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert f"red is in {scenes['init']} but not in {scenes['two']}" in err


@pytest.mark.sim
def test_images_of_different_sizes(scenes, capsys):
    small = cv2.resize(cv2.imread(scenes["goal"]), (160, 120))
    path = scenes["root"] / "small.png"
    cv2.imwrite(str(path), small)
    assert main(["plan-images", scenes["init"], str(path)]) == 2
    assert "320x240" in one_line_error(capsys, "tamp: error:")


def _grey(tmp_path, name: str, size: tuple[int, int] = (160, 120)) -> str:
    return _save(tmp_path / name, np.full((size[1], size[0], 3), 110, np.uint8))


def test_missing_and_unreadable_images(tmp_path, capsys):
    grey = _grey(tmp_path, "grey.png")
    assert main(["plan-images", str(tmp_path / "nothing.png"), grey]) == 2
    assert "no image file at" in one_line_error(capsys, "tamp: error:")
    text = tmp_path / "text.png"
    text.write_text("not an image")
    assert main(["plan-images", grey, str(text)]) == 2
    assert "cannot read" in one_line_error(capsys, "tamp: error:")


def test_no_blocks_and_too_small_images(tmp_path, capsys):
    grey = _grey(tmp_path, "grey.png")
    assert main(["plan-images", grey, grey]) == 2
    assert "no blocks found" in one_line_error(capsys, "tamp: error:")
    tiny = _grey(tmp_path, "tiny.png", (6, 4))
    assert main(["plan-images", tiny, tiny]) == 2
    assert "6x4" in one_line_error(capsys, "tamp: error:")


def test_missing_checkpoints(tmp_path, capsys, monkeypatch):
    from tamp.cli import images

    assert LATPLAN_CHECKPOINT.is_file()  # shipped with the package
    grey = _grey(tmp_path, "grey.png")
    missing = str(tmp_path / "none.pt")
    assert main(["plan-images", grey, grey, "--checkpoint", missing]) == 2
    assert missing in one_line_error(capsys, "tamp: error:")
    monkeypatch.setattr(images, "LATPLAN_CHECKPOINT", tmp_path / "support-latplan.pt")
    assert main(["plan-images", grey, grey, "--image-scene", "latplan"]) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert "support-latplan.pt" in err and "--checkpoint" in err
