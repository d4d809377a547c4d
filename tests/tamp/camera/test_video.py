"""Episode videos: MP4 and GIF files are written frame by frame; bad frames are clear errors;
an episode's video is rendered at 640x480 by a process of its own from the world's snapshots."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from PIL import Image, ImageSequence

from motion.trajectory import JointTrajectory
from robots.panda import PANDA
from tamp.scene import Pose, layout
from tamp.sim import SIMULATORS, make_simulator
from tamp.video import EpisodeVideo, VideoWriter
from task.errors import TampError
from task.problem import TABLE

COLOURS = ((200, 30, 30), (30, 200, 30), (30, 30, 200), (200, 200, 30), (30, 200, 200))  # RGB
H, W = 48, 64
BAND = 19  # rows of the caption band at the top of every captioned frame


def _decode(path) -> list[np.ndarray]:
    """Every frame of the written file as (H, W, 3) RGB uint8, decoded independently."""
    if path.suffix == ".gif":
        with Image.open(path) as gif:
            return [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(gif)]
    capture = cv2.VideoCapture(str(path))
    frames = []
    while (read := capture.read())[0]:
        frames.append(cv2.cvtColor(read[1], cv2.COLOR_BGR2RGB))
    capture.release()
    return frames


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_frames_are_written_to_a_video_file(tmp_path, suffix):
    video = VideoWriter(tmp_path / f"clip{suffix}", fps=10)
    for k, rgb in enumerate(COLOURS):
        video.write(np.full((H, W, 3), rgb, dtype=np.uint8), caption=f"frame {k}")
    path = video.close()
    assert path == tmp_path / f"clip{suffix}" and video.frames == len(COLOURS)
    frames = _decode(path)
    assert len(frames) == len(COLOURS)
    assert all(f.shape == (H, W, 3) for f in frames)
    tolerance = 12 if suffix == ".mp4" else 3  # MP4 is lossy; a GIF palette holds these exactly
    for frame, rgb in zip(frames, COLOURS, strict=True):  # in order, each its own colour
        below = frame[BAND + 4 :].reshape(-1, 3).mean(0)  # clear of the band and its edge blur
        np.testing.assert_allclose(below, rgb, atol=tolerance)
        assert frame[2 : BAND - 4].mean() < 60  # the dark caption band (white text on black)


def test_no_frames_means_no_file(tmp_path):
    video = VideoWriter(tmp_path / "empty.mp4")
    assert video.close() is None
    assert not (tmp_path / "empty.mp4").exists()


def test_bad_video_inputs_are_clear_errors(tmp_path):
    with pytest.raises(TampError, match="must end in"):
        VideoWriter(tmp_path / "clip.avi")
    with pytest.raises(TampError, match="uint8"):
        VideoWriter(tmp_path / "clip.mp4").write(np.zeros((4, 4), dtype=np.float32))


def test_captions_scale_with_the_frame_width(tmp_path):
    video = VideoWriter(tmp_path / "wide.mp4", fps=10)
    video.write(np.full((480, 640, 3), COLOURS[1], dtype=np.uint8), "a caption", ["a note"])
    (frame,) = _decode(video.close())
    assert frame.shape == (480, 640, 3)
    band = frame[2:32]  # 36 rows at twice the base width
    assert band.mean() < 60 and (band > 200).any()  # dark, with white text
    np.testing.assert_allclose(frame[44:400].reshape(-1, 3).mean(0), COLOURS[1], atol=12)
    assert frame[450:470, 4:100].mean() < 100  # the note's dark box at the bottom left


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_an_episode_video_is_rendered_at_640x480_in_its_own_process(tmp_path, sim_name):
    entities = ("a", "b")
    video = EpisodeVideo(tmp_path / "clip.mp4", fps=10)
    with make_simulator(sim_name, entities, layout(entities, (TABLE, TABLE), seed=1)) as sim:
        for k in range(3):
            video.write(sim, f"frame {k}", ["a on table 1.00"])
            sim.set_block_pose("a", Pose((0.45, -0.15 + 0.15 * k, 0.025)))  # red, along +y
            sim.run(JointTrajectory.hold(PANDA.q_home, 0.1, sim.dt), "open")
        frames = _decode(video.close())
    assert video.frames == len(frames) == 3
    assert all(f.shape == (480, 640, 3) and f[40:440].std() > 10 for f in frames)  # not blank
    red = [np.argwhere((f[..., 0] > 120) & (f[..., 1] < 80) & (f[..., 2] < 80)) for f in frames]
    assert all(len(r) > 400 for r in red)  # the red block, about 0.1% of the frame or more
    assert red[2][:, 1].mean() > red[1][:, 1].mean() + 20  # +y is to the right in the picture


@pytest.mark.sim
def test_a_failing_video_renderer_is_a_clear_error(tmp_path):
    video = EpisodeVideo(tmp_path / "huge.mp4", size=(4000, 3000))
    with make_simulator("mujoco", ("a",), layout(("a",), (TABLE,), seed=0)) as sim:
        video.write(sim)
        with pytest.raises(TampError, match=r"huge\.mp4.*offscreen buffer"):
            video.close()
    assert EpisodeVideo(tmp_path / "none.mp4").close() is None
