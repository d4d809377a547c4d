"""``tamp bench latplan`` on a tiny fake LatPlan folder: two instances rendered here with our own
LatPlan scene (PyBullet), their PDDL and manifest rows. Only the plumbing is tested (every row
gets a status, the table prints, the files are written) and the one-line errors; the shipped
cube checkpoint stands in for a LatPlan one there, so what it reads is not asserted; one test
runs the shipped LatPlan checkpoint and asserts that it reads these renders right.
"""

from __future__ import annotations

import csv
import json

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
STATUSES = {"valid", "inexecutable", "non_goal_reaching", "no_plan", "unreadable"}
# name -> (init, goal, optimal 4-op length): red on blue -> all on the table; green onto red
INSTANCES = {
    "007-001": ((NAMES[1], TABLE, TABLE, TABLE), (TABLE, TABLE, TABLE, TABLE), 2),
    "014-002": ((TABLE, TABLE, TABLE, TABLE), (TABLE, TABLE, NAMES[0], TABLE), 2),
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A LatPlan-40-shaped folder of two instances."""
    from tamp.camera.latplan import downscale, latplan_camera, latplan_scene
    from tamp.camera.render import StateRenderer

    root = tmp_path_factory.mktemp("latplan")
    (root / "pddl").mkdir()
    (root / "pddl" / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    rows = []
    with StateRenderer("pybullet", latplan_scene(), latplan_camera()) as renderer:
        for k, (name, (init, goal, optimal)) in enumerate(INSTANCES.items()):
            where = root / "prob-cylinders-4" / name
            (where / "image_tr").mkdir(parents=True)
            for j, (kind, state) in enumerate((("init", init), ("goal", goal))):
                rgb = renderer.render(NAMES, state, seed=10 * k + j, colours=[0, 1, 2, 3])
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


@pytest.mark.sim
def test_state_and_frozen_rows_table_and_files(folder, tmp_path, capsys):
    torch.set_num_threads(1)
    out = tmp_path / "out"
    args = [
        "bench",
        "latplan",
        "--data",
        str(folder),
        "--checkpoint",
        str(CHECKPOINT),
        "--modes",
        "state,frozen",
        "--seeds",
        "1",
        "--no-progress",
        "--out",
        str(out),
        *FAST,
    ]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "LatPlan AMA+4 (as the paper cites it)" in printed and "31/40" in printed
    assert "ours, from the true states" in printed
    for res in ("150x100", "45x30"):
        assert f"ours, frozen perception, {res}" in printed
    with (out / "instances.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 2 + 2 * 2  # state once, frozen per resolution
    assert {r["status"] for r in rows} <= STATUSES
    assert all(r["error"] for r in rows if r["status"] == "unreadable")
    assert {r["optimal"] for r in rows} == {"2"}
    body = json.loads((out / "results.json").read_text())
    assert body["instances"] == list(INSTANCES) and body["modes"] == ["state", "frozen"]
    assert [(s["resolution"], s["mode"]) for s in body["summary"]] == [
        ("-", "state"),
        ("150x100", "frozen"),
        ("45x30", "frozen"),
    ]
    assert body["summary"][0]["valid"]["mean"] == 2  # from the true states: solved


@pytest.mark.sim
def test_the_shipped_latplan_model_reads_our_own_renders(folder, tmp_path, capsys):
    """The default checkpoint (perception/support-latplan.pt) on the two instances rendered
    here: every state read right and every plan valid, at both resolutions."""
    torch.set_num_threads(1)
    out = tmp_path / "shipped"
    args = [
        "bench",
        "latplan",
        "--data",
        str(folder),
        "--modes",
        "frozen",
        "--seeds",
        "1",
        "--no-progress",
        "--out",
        str(out),
    ]
    assert main(args) == 0
    with (out / "instances.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 4
    assert {r["status"] for r in rows} == {"valid"}, rows


def test_state_mode_needs_no_checkpoint_and_json(folder, tmp_path, capsys):
    torch.set_num_threads(1)
    args = [
        "bench",
        "latplan",
        "--data",
        str(folder),
        "--checkpoint",
        str(tmp_path / "no.pt"),
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
    assert missing in err and "--checkpoint FILE.pt" in err
    assert main(["bench", "latplan", "--data", str(folder), "--res", "64x64"]) == 2
    assert "150x100, 45x30" in one_line_error(capsys, "tamp: error:")
    assert main(["bench", "latplan", "--data", str(folder), "--modes", "frozen,blurry"]) == 2
    assert "'blurry'" in one_line_error(capsys, "tamp: error:")
