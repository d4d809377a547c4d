"""``tamp bench latplan`` on a tiny fake LatPlan folder: four instances rendered here with our
own LatPlan scene (PyBullet), their PDDL and manifest rows. The shipped LatPlan checkpoint must
give every image row the status its instance calls for: two plain instances are read right and
planned validly; one whose PDDL goal is not the goal its image shows is read right and planned
for the image, so the validator against its PDDL says ``non_goal_reaching``; one whose goal
image lacks a block is ``unreadable`` with its error line. A checkpoint trained on the other
(cube) scene, LatPlan's documented negative control, is warned about and recorded.
"""

from __future__ import annotations

import csv
import json
from typing import NamedTuple

import cv2
import numpy as np
import pytest
import torch

from perception import CHECKPOINT
from tamp.cli import main
from task import data
from task.domains.blocksworld_pddl import to_pddl
from task.problem import TABLE, Problem
from tests.cli_check import one_line_error

NAMES = ("red", "blue", "green", "black")  # palette indices 0..3 of the latplan scene
FAST = ["--iters", "20", "--restarts", "4", "--max-windows", "6", "--threads", "1"]
ON_TABLE = (TABLE, TABLE, TABLE, TABLE)


class Case(NamedTuple):
    """One fake instance; a block missing from ``shown`` is not drawn in the goal image."""

    init: tuple[str, ...]
    shown: tuple[str, ...]  # the goal the goal image shows
    goal: tuple[str, ...]  # the goal in the instance's PDDL
    optimal: int  # 4-op length
    status: str  # what every image row of it must say


INSTANCES = {
    "007-001": Case((NAMES[1], TABLE, TABLE, TABLE), ON_TABLE, ON_TABLE, 2, "valid"),
    "014-002": Case(
        ON_TABLE, (TABLE, TABLE, NAMES[0], TABLE), (TABLE, TABLE, NAMES[0], TABLE), 2, "valid"
    ),
    # the goal image shows blue on green, the PDDL wants red on green
    "021-003": Case(
        ON_TABLE,
        (TABLE, NAMES[2], TABLE, TABLE),
        (NAMES[2], TABLE, TABLE, TABLE),
        2,
        "non_goal_reaching",
    ),
    # the goal image has no black block
    "028-004": Case((NAMES[1], TABLE, TABLE, TABLE), ON_TABLE[:3], ON_TABLE, 2, "unreadable"),
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A LatPlan-40-shaped folder of the four `INSTANCES`."""
    from tamp.camera.latplan import downscale, latplan_camera, latplan_scene
    from tamp.camera.render import StateRenderer

    root = tmp_path_factory.mktemp("latplan")
    (root / "pddl").mkdir()
    (root / "pddl" / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    rows = []
    with StateRenderer("pybullet", latplan_scene(), latplan_camera()) as renderer:
        for k, (name, (init, shown, goal, optimal, _)) in enumerate(INSTANCES.items()):
            where = root / "prob-cylinders-4" / name
            (where / "image_tr").mkdir(parents=True)
            for j, (kind, state) in enumerate((("init", init), ("goal", shown))):
                blocks = NAMES[: len(state)]
                colours = list(range(len(state)))
                rgb = renderer.render(blocks, state, seed=10 * k + j, colours=colours)
                bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
                rgba = np.dstack([bgr, np.full(rgb.shape[:2], 255, np.uint8)])
                cv2.imwrite(str(where / "image_tr" / f"{kind}.png"), rgba)
                cv2.imwrite(str(where / f"{kind}.png"), downscale(bgr[None], (45, 30))[0])
            atoms = tuple(zip(NAMES, goal, strict=True))
            text = to_pddl(Problem(f"latplan-{name}", "blocksworld", NAMES, init, atoms))
            (root / "pddl" / f"{name}.pddl").write_text(text)
            rows.append({"problem": name, "opt_len_4op": optimal, "pddl_file": f"pddl/{name}.pddl"})
    with (root / "manifest.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, ["problem", "opt_len_4op", "pddl_file"])
        writer.writeheader()
        writer.writerows(rows)
    return root


def _bench(folder, out, *options: str) -> list[dict]:
    argv = ["bench", "latplan", "--data", str(folder), "--seeds", "1", "--no-progress"]
    assert main([*argv, "--out", str(out), *options, *FAST]) == 0
    with (out / "instances.csv").open() as handle:
        return list(csv.DictReader(handle))


@pytest.mark.sim
def test_every_row_has_the_status_its_instance_calls_for(folder, tmp_path, capsys):
    """The shipped LatPlan checkpoint (the default) on the renders made here."""
    torch.set_num_threads(1)
    out = tmp_path / "out"
    rows = _bench(folder, out, "--modes", "state,frozen")
    printed = capsys.readouterr()
    assert "LatPlan AMA+4 (as the paper cites it)" in printed.out and "31/40" in printed.out
    assert "ours, from the true states" in printed.out and "warning" not in printed.err
    for res in ("150x100", "45x30"):
        assert f"ours, frozen perception, {res}" in printed.out
    assert len(rows) == 4 + 4 * 2  # state once, frozen per resolution
    for row in rows:
        _, shown, goal, optimal, status = INSTANCES[row["instance"]]
        where = f"{row['instance']} {row['mode']} {row['resolution']}"
        if row["mode"] == "state":  # from the true state: every PDDL problem is solved
            assert row["status"] == "valid" and row["length"] == str(optimal), where
            continue
        assert row["status"] == status, (where, row)
        if status == "unreadable":
            assert "black is in" in row["error"] and row["length"] == "", where
            continue
        assert row["init_read"] == "True", where
        assert row["goal_read"] == str(shown == goal), where  # read against the PDDL goal
        assert row["length"] == str(optimal) and row["error"] == "", where
    body = json.loads((out / "results.json").read_text())
    assert body["instances"] == list(INSTANCES) and body["modes"] == ["state", "frozen"]
    assert body["checkpoint_scene"] == "latplan" and "warnings" not in body
    assert [(s["resolution"], s["mode"], s["valid"]["mean"]) for s in body["summary"]] == [
        ("-", "state", 4),
        ("150x100", "frozen", 2),
        ("45x30", "frozen", 2),
    ]
    assert body["summary"][1]["statuses"] == {"valid": 2, "non_goal_reaching": 1, "unreadable": 1}


@pytest.mark.sim
def test_a_checkpoint_of_the_cube_scene_is_warned_about_and_recorded(folder, tmp_path, capsys):
    """The cube checkpoint on LatPlan images is a documented negative control: it runs, but
    says loudly that its rows are no LatPlan result, and results.json records why."""
    torch.set_num_threads(1)
    out = tmp_path / "cube"
    options = ("--checkpoint", str(CHECKPOINT), "--modes", "frozen", "--res", "45x30")
    rows = _bench(folder, out, *options, "--limit", "1")
    err = capsys.readouterr().err
    assert len(rows) == 1
    assert f"warning: {CHECKPOINT} was trained on the cubes scene, not latplan" in err
    body = json.loads((out / "results.json").read_text())
    assert body["checkpoint_scene"] == "cubes"
    assert body["warnings"] == [
        f"{CHECKPOINT} was trained on the cubes scene, not latplan: its image rows measure a "
        "mismatched model (a negative control), not LatPlan perception"
    ]


def test_state_mode_needs_no_checkpoint_and_json(folder, tmp_path, capsys):
    torch.set_num_threads(1)
    args = [
        "bench",
        "latplan",
        "--data",
        str(folder),
        "--modes",
        "state",
        "--seeds",
        "2",
        "--limit",
        "1",
        "--json",
        "--no-progress",
        *FAST,
    ]
    assert main(args) == 0
    body = json.loads(capsys.readouterr().out)
    (summary,) = body["summary"]
    assert body["n"] == 1 and summary["seeds"] == [0, 1] and body["checkpoint"] is None


def test_missing_data_checkpoint_and_bad_options(folder, tmp_path, capsys):
    assert main(["bench", "latplan", "--data", str(tmp_path / "none")]) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert "LatPlan-40 data not found" in err and "--data DIR" in err
    missing = str(tmp_path / "none.pt")
    assert main(["bench", "latplan", "--data", str(folder), "--checkpoint", missing]) == 2
    err = one_line_error(capsys, "tamp: error:")
    assert missing in err and "--checkpoint" in err
    assert main(["bench", "latplan", "--data", str(folder), "--res", "64x64"]) == 2
    assert "150x100, 45x30" in one_line_error(capsys, "tamp: error:")
    assert main(["bench", "latplan", "--data", str(folder), "--modes", "frozen,blurry"]) == 2
    assert "'blurry'" in one_line_error(capsys, "tamp: error:")
