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


@pytest.fixture(scope="module")
def latplan_pair(tmp_path_factory):
    """PNG paths of two LatPlan-like renders (red, blue, green and black cylinders), made here
    by the project's own generator (`tamp.camera.latplan.generate`)."""
    from tamp.camera import latplan

    root = tmp_path_factory.mktemp("latplan")
    images = latplan.generate(2, seed=0, sims=("pybullet",))[latplan.SIZES[0]].images
    return [_save(root / f"{k}.png", im) for k, im in enumerate(images)]


@pytest.mark.sim
def test_cube_renders_read_as_latplan_are_refused_naming_the_colours_and_the_scene(scenes, capsys):
    """Not a VALID plan of two of the three cubes: LatPlan has no purple block."""
    argv = ["plan-images", scenes["init"], scenes["goal"], "--image-scene", "latplan"]
    assert main(argv) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert "shows red, green, purple" in err and "the latplan scene has no purple block" in err
    assert err.endswith("read them with --image-scene cubes"), err


@pytest.mark.sim
def test_a_latplan_pair_read_as_cubes_is_refused_naming_black_and_latplan(latplan_pair, capsys):
    """Not a 1-move plan of three cylinders: the black one would be lost."""
    assert main(["plan-images", *latplan_pair]) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert "shows red, blue, green, black" in err and "the cubes scene has no black block" in err
    assert err.endswith("read them with --image-scene latplan"), err


@pytest.mark.sim
def test_a_huge_photograph_is_read_at_the_models_size_as_its_downscaled_copy(
    scenes, capsys, monkeypatch
):
    """A 3200x2400 copy of each render (the renders upscaled tenfold) reads the same states as
    the renders; every image the segmentation sees fits the model's 320x240 input."""
    from perception import perceive
    from tamp.camera import image_pair

    huge = []
    for key in ("init", "goal"):
        big = cv2.resize(cv2.imread(scenes[key]), (3200, 2400), interpolation=cv2.INTER_NEAREST)
        huge.append(str(scenes["root"] / f"huge_{key}.png"))
        cv2.imwrite(huge[-1], big)
    sizes = []

    def spy(real):
        def seen(image, *args, **kwargs):
            sizes.append(image.shape[:2])
            return real(image, *args, **kwargs)

        return seen

    monkeypatch.setattr(image_pair, "present", spy(image_pair.present))
    monkeypatch.setattr(perceive, "find_boxes", spy(perceive.find_boxes))
    readings = []
    for pair in ([scenes["init"], scenes["goal"]], huge):
        args = ["plan-images", *pair, "--horizon", "1", "--threads", "1", "--json"]
        main(args)
        record = json.loads(capsys.readouterr().out)
        readings.append((record["blocks"], record["perceived_init"], record["perceived_goal"]))
    assert readings[0] == readings[1]
    assert readings[1][1] == dict(zip(NAMES, INIT, strict=True))
    assert sizes and all(h <= 240 and w <= 320 for h, w in sizes), sorted(set(sizes))
