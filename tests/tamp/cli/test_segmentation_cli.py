"""``tamp bench segmentation``: the colour segmentation's thresholds checked on datasets, with
its table, its results.json and its one-line refusals.

The first test draws three LatPlan-like scenes whose outcome is known: every block plainly
shown; a tinted black (dark olive, chroma over ``dark_chroma``) that no threshold set finds; and
a black block on a near-black floor, only 7 grey levels below it, that only the unguarded
thresholds (``dark_contrast`` 0) find.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from perception import CHECKPOINT
from perception import data as pdata
from tamp.cli import main
from tests.cli_check import one_line_error

LATPLAN_CHECKPOINT = CHECKPOINT.with_name("support-latplan.pt")
PALETTE = np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0], [0, 0, 0]], np.float32)  # red blue green black
SIDE = 17  # block width and height in pixels at 150x100
VIVID = [(220, 30, 30), (30, 30, 220), (30, 220, 30)]  # RGB of the red, blue and green blocks


def _scene(floor: int, black: tuple[int, int, int]) -> np.ndarray:
    """(100, 150, 3) uint8: a flat grey floor, four blocks side by side on it, the last drawn
    in ``black``; no grain, so every pixel value below is exact."""
    image = np.full((100, 150, 3), floor, np.uint8)
    for k, rgb in enumerate([*VIVID, black]):
        x = 10 + 35 * k
        image[60 : 60 + SIDE, x : x + SIDE] = rgb
    return image


def _dataset(path) -> str:
    images = np.stack(
        [
            _scene(120, (25, 25, 25)),  # found by both threshold sets
            _scene(120, (60, 60, 20)),  # dark olive: chroma 40 >= dark_chroma 32, never found
            _scene(12, (5, 5, 5)),  # 7 levels below the floor: dark_contrast 10 cuts it
        ]
    )
    data = pdata.SupportData(
        images=images,
        colours=np.tile(np.arange(4, dtype=np.int8), (3, 1)),
        supports=np.full((3, 4), pdata.TABLE, np.int8),  # every block on the table
        palette=PALETTE,
        meta={"scene": "latplan", "made_by": "drawn by test_segmentation_cli.py"},
    )
    return str(pdata.save(path, data))


def _row(printed: str, *first: str) -> list[str]:
    """The one printed line whose first words are ``first``, split into words."""
    lines = [line.split() for line in printed.splitlines()]
    found = [words for words in lines if words[: len(first)] == list(first)]
    assert len(found) == 1, printed
    return found[0]


def test_the_table_and_results_json_count_what_each_threshold_set_finds(capsys, tmp_path):
    data, out = _dataset(tmp_path / "drawn.npz"), tmp_path / "out"
    argv = ["bench", "segmentation", data, "--checkpoint", str(LATPLAN_CHECKPOINT)]
    assert main([*argv, "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    body = json.loads((out / "results.json").read_text())

    assert body["benchmark"] == "segmentation"
    assert body["config"] == {
        "data": [data],
        "checkpoint": str(LATPLAN_CHECKPOINT),
        "device": "cpu",
    }
    assert body["machine"]["command"] == f"tamp {' '.join(argv)} --out {out} --no-progress"
    assert "commit" in body["machine"] and "dirty" in body["machine"]
    assert body["input_hw"] == [100, 150]  # the checkpoint's; these images already are
    assert body["thresholds"]["current"]["dark_contrast"] == 10
    assert body["thresholds"]["unguarded"] == {"max_area_share": 1.0, "dark_contrast": 0}

    f = body["files"][data]
    assert f["images"] == 3 and f["blocks_shown"] == {"#0": 3, "#1": 3, "#2": 3, "#3": 3}
    assert f["blocks_found"]["current"] == {"#0": 3, "#1": 3, "#2": 3, "#3": 1}
    assert f["blocks_found"]["unguarded"] == {"#0": 3, "#1": 3, "#2": 3, "#3": 2}
    assert f["images_with_every_block_found"] == 1
    assert (f["scenes_read"], f["unreadable"]) == (1, 2)  # the model reads only found scenes
    assert f["scenes_right"] in (0, 1)
    assert f["scene_accuracy"] == f["scenes_right"] / f["scenes_read"]
    margins = f["dark_margins"]  # only the first image's black region passes every threshold
    assert margins["images"] == 1
    assert margins["value (<= dark_value)"] == {
        "threshold": 70,
        "worst": 25.0,
        "p95": 25.0,
        "median": 25.0,
    }
    assert margins["chroma (< dark_chroma)"]["worst"] == 0.0
    assert margins["ratio to background (<= dark_ratio)"]["worst"] == pytest.approx(25 / 120)
    assert margins["contrast (>= dark_contrast)"]["worst"] == 95.0

    read = [f"{f['scenes_right']}/1", f"{f['relation_accuracy']:.1%}"]
    current, unguarded = _row(printed, data, "current"), _row(printed, "unguarded")
    assert current == [data, "current", "3", "3/3", "3/3", "3/3", "1/3", "1", *read]
    assert unguarded == ["unguarded", "3", "3/3", "3/3", "3/3", "2/3", "-", "-", "-"]
    assert "colours: #0 (255, 0, 0), #1 (0, 0, 255), #2 (0, 255, 0), #3 (0, 0, 0)" in printed
    assert _row(printed, data, "1", "value")[-4:] == ["70", "25", "25", "25"]
    assert _row(printed, "1", "chroma")[-4:] == ["32", "0", "0", "0"]
    assert _row(printed, "1", "ratio")[-4:] == ["0.50", "0.21", "0.21", "0.21"]
    assert _row(printed, "1", "contrast")[-4:] == ["10", "95", "95", "95"]
    assert f"wrote results.json to {out}" in printed

    assert main([*argv, "--json", "--no-progress"]) == 0  # the same report on stdout
    shown = json.loads(capsys.readouterr().out)
    assert shown["files"] == body["files"] and shown["thresholds"] == body["thresholds"]


@pytest.mark.sim
def test_renders_from_the_dataset_command_are_read_at_the_checkpoints_size(capsys, tmp_path):
    big = tmp_path / "fresh.npz"
    made = ["perception", "dataset", "--image-scene", "latplan", "--n", "2", "--seed", "9"]
    assert main([*made, "--out", str(big), "--no-progress"]) == 0
    small = str(tmp_path / "fresh_45x30.npz")
    capsys.readouterr()
    argv = ["bench", "segmentation", str(big), small, "--checkpoint", str(LATPLAN_CHECKPOINT)]
    assert main([*argv, "--json", "--no-progress"]) == 0
    body = json.loads(capsys.readouterr().out)
    assert list(body["files"]) == [str(big), small]
    for f in body["files"].values():
        assert f["images"] == 2 and sum(f["blocks_shown"].values()) == 8
        assert f["scenes_read"] + f["unreadable"] == 2
        for label in ("current", "unguarded"):
            assert all(f["blocks_found"][label][c] <= n for c, n in f["blocks_shown"].items())


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["missing.npz"], "no such file: missing.npz"),
        (["DATA", "DATA"], "given twice: DATA"),
        (["NOT_NPZ"], "is not a support dataset"),
        (["DATA", "--out", "DATA"], "is a file; give a folder"),
    ],
)
def test_bad_input_is_one_line_before_any_work(capsys, tmp_path, monkeypatch, extra, needle):
    from tamp.bench.vision import segmentation

    def no_work(*args, **kwargs):
        raise AssertionError("the check ran before the input was refused")

    monkeypatch.setattr(segmentation, "check", no_work)
    data = _dataset(tmp_path / "d.npz")
    (tmp_path / "text.npz").write_text("not a dataset")
    names = {"DATA": data, "NOT_NPZ": str(tmp_path / "text.npz")}
    argv = [names.get(a, a) for a in extra]
    assert main(["bench", "segmentation", *argv, "--checkpoint", str(LATPLAN_CHECKPOINT)]) == 2
    assert needle.replace("DATA", data) in one_line_error(capsys)


def test_a_checkpoint_of_the_other_scene_is_refused(capsys, tmp_path):
    data = _dataset(tmp_path / "d.npz")
    assert main(["bench", "segmentation", data, "--checkpoint", str(CHECKPOINT)]) == 2
    assert "shows the latplan scene but the checkpoint was trained on cubes" in one_line_error(
        capsys
    )


def test_a_missing_checkpoint_is_one_line(capsys, tmp_path):
    data = _dataset(tmp_path / "d.npz")
    assert main(["bench", "segmentation", data, "--checkpoint", "none.pt"]) == 2
    assert "no such file: none.pt" in one_line_error(capsys)
