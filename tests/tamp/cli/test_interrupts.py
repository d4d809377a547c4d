"""Ctrl-C keeps what was done: ``tamp run --out`` writes the report so far (status
``interrupted``) and a video that plays, and exits 130."""

from __future__ import annotations

import json
import multiprocessing
import os
import signal

import cv2
import pytest

from tamp.cli import main
from tamp.loop import Episode


def _frames(path) -> int:
    capture = cv2.VideoCapture(str(path))
    count = 0
    while capture.read()[0]:
        count += 1
    capture.release()
    return count


@pytest.mark.sim
def test_ctrl_c_in_tamp_run_keeps_the_report_and_a_playable_video(tmp_path, monkeypatch, capsys):
    real = Episode.step

    def step(self, p):
        if len(p.moves) == 1:  # Ctrl-C after the first move: the terminal sends it to the
            for child in multiprocessing.active_children():  # whole group, the renderer too
                os.kill(child.pid, signal.SIGINT)
            raise KeyboardInterrupt
        real(self, p)

    monkeypatch.setattr(Episode, "step", step)
    out = tmp_path / "out"
    assert main(["run", "--sim", "pybullet", "--out", str(out)]) == 130
    captured = capsys.readouterr()
    assert captured.err.endswith("tamp: interrupted\n")
    assert "interrupted (Ctrl-C after 1 moves)" in captured.out
    report = json.loads((out / "report.json").read_text())
    assert report["status"] == "interrupted" and len(report["moves"]) == 1
    assert report["config"]["sim"] == "pybullet"
    assert _frames(out / "episode.mp4") > 0  # finished: the moov atom is there


@pytest.mark.sim
def test_ctrl_c_in_a_geometric_run_keeps_the_report_and_a_playable_video(
    tmp_path, monkeypatch, capsys
):
    """A scene file's geometric episode (`tamp.geo.episode.run_geo_episode`) stopped by
    Ctrl-C in its second move: report.json says interrupted with the first move, the video
    plays, exit 130."""
    import tamp.geo.episode as geo_episode

    real = geo_episode._act
    calls = []

    def act(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:  # Ctrl-C in the second move, the renderer's process told too
            for child in multiprocessing.active_children():
                os.kill(child.pid, signal.SIGINT)
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(geo_episode, "_act", act)
    out = tmp_path / "out"
    argv = ["run", "--scene", "tray", "--goal", "(in a tray)", "--out", str(out)]
    assert main(argv) == 130
    captured = capsys.readouterr()
    assert captured.err.endswith("tamp: interrupted\n")
    assert "interrupted (Ctrl-C after 1 moves)" in captured.out
    report = json.loads((out / "report.json").read_text())
    assert report["status"] == "interrupted" and len(report["moves"]) == 1
    assert not report["reached_goal"]
    assert _frames(out / "episode.mp4") > 0  # finished: the moov atom is there
