"""Episode videos: MP4 and GIF files are written frame by frame; bad frames are clear errors."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.video import VideoWriter
from task.errors import TampError


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_frames_are_written_to_a_video_file(tmp_path, suffix):
    video = VideoWriter(tmp_path / f"clip{suffix}", fps=10)
    for k in range(5):
        frame = np.full((48, 64, 3), 40 * k, dtype=np.uint8)
        video.write(frame, caption=f"frame {k}")
    path = video.close()
    assert path is not None and path.stat().st_size > 100
    assert video.frames == 5


def test_no_frames_means_no_file(tmp_path):
    video = VideoWriter(tmp_path / "empty.mp4")
    assert video.close() is None
    assert not (tmp_path / "empty.mp4").exists()


def test_bad_video_inputs_are_clear_errors(tmp_path):
    with pytest.raises(TampError, match="must end in"):
        VideoWriter(tmp_path / "clip.avi")
    with pytest.raises(TampError, match="uint8"):
        VideoWriter(tmp_path / "clip.mp4").write(np.zeros((4, 4), dtype=np.float32))
