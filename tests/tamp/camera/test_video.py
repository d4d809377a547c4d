"""Episode videos: MP4 and GIF files are written frame by frame; bad frames are clear errors."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from PIL import Image, ImageSequence

from tamp.video import VideoWriter
from task.errors import TampError

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
