"""``tamp bench poses``: the driver's numbers, the table and the artefacts, on a few scenes."""

from __future__ import annotations

import csv
import json
import math

import pytest

from tamp.bench.vision.poses import BlockRow, summarise, yaw_error
from tamp.cli import main


def test_yaw_error_is_modulo_the_cubes_quarter_turn():
    assert yaw_error(0.01, -0.01) == pytest.approx(math.degrees(0.02))
    assert yaw_error(math.pi / 4 - 0.01, -math.pi / 4 + 0.01) == pytest.approx(math.degrees(0.02))
    assert yaw_error(0.3, 0.3 + math.pi / 2) == pytest.approx(0.0, abs=1e-9)


def test_summary_splits_free_and_covered_tops_and_counts_misses():
    rows = [
        BlockRow("s", 0, "a", 2, 0, False, "", 2.0, 0, 0, 0, 0.5),
        BlockRow("s", 0, "b", 2, 1, True, "", 1.0, 0, 0, 0, 0.1),
        BlockRow("s", 1, "a", 1, 0, True, "block a shows 0 pixels", None, None, None, None, None),
    ]
    s = summarise(rows)
    assert (s["all"]["estimated"], s["all"]["blocks"]) == (2, 3)
    assert (s["top"]["estimated"], s["top"]["blocks"]) == (1, 2)
    assert s["covered"]["position_mm"]["max"] == 2.0
    assert s["all"]["position_mm"]["mean"] == pytest.approx(1.5)


@pytest.mark.sim
def test_bench_poses_prints_the_table_and_writes_artefacts(capsys, tmp_path):
    argv = ["bench", "poses", "--sim", "pybullet", "--n", "2", "--no-progress"]
    assert main([*argv, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "pybullet  all" in out and "top free" in out and "covered" in out
    body = json.loads((tmp_path / "results.json").read_text())
    assert body["config"]["sims"] == ["pybullet"] and "machine" in body
    total = body["summary"]["pybullet"]["all"]
    rows = list(csv.DictReader((tmp_path / "blocks.csv").open()))
    assert len(rows) == total["blocks"] and total["estimated"] == total["blocks"]
    assert total["position_mm"]["max"] < 3.0


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--sim", "gazebo"], "unknown simulator"),
        (["--min-blocks", "5", "--max-blocks", "4"], "--min-blocks 5 is more than --max-blocks 4"),
    ],
)
def test_bad_options_exit_2_with_one_line(capsys, argv, needle):
    assert main(["bench", "poses", "--n", "1", "--no-progress", *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1
