"""Episode videos: camera frames with a caption, streamed to MP4 (OpenCV) or GIF (Pillow).

Frames are written as they are rendered, so a long episode never holds its video in memory.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from task.errors import TampError

FORMATS = (".mp4", ".gif")


class VideoWriter:
    """``write(rgb, caption)`` appends a frame (H, W, 3) uint8; ``close()`` finishes the file."""

    def __init__(self, path: str | Path, fps: float = 20.0) -> None:
        self.path = Path(path)
        if self.path.suffix not in FORMATS:
            raise TampError(f"video file must end in one of {FORMATS}, got {self.path.name!r}")
        self.fps = fps
        self.frames = 0
        self._mp4: cv2.VideoWriter | None = None
        self._gif: list = []

    def write(self, rgb: np.ndarray, caption: str = "", notes: Sequence[str] = ()) -> None:
        """Append a frame; ``caption`` on a band at the top, ``notes`` (short lines, e.g. the
        perceived soft state) at the bottom left."""
        if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
            raise TampError(f"a video frame must be (H, W, 3) uint8, got {rgb.shape} {rgb.dtype}")
        bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
        if caption:
            cv2.rectangle(bgr, (0, 0), (bgr.shape[1], 18), (0, 0, 0), -1)
            cv2.putText(bgr, caption, (4, 13), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 1)
        h = bgr.shape[0]
        for k, line in enumerate(reversed(list(notes))):
            y = h - 6 - 13 * k
            cv2.rectangle(bgr, (0, y - 10), (8 + 6 * len(line), y + 3), (0, 0, 0), -1)
            cv2.putText(bgr, line, (4, y), cv2.FONT_HERSHEY_SIMPLEX, 0.35, (255, 255, 255), 1)
        if self.path.suffix == ".gif":
            self._gif.append(bgr[..., ::-1].copy())
        else:
            if self._mp4 is None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                h, w = bgr.shape[:2]
                fourcc = cv2.VideoWriter_fourcc(*"mp4v")
                self._mp4 = cv2.VideoWriter(str(self.path), fourcc, self.fps, (w, h))
                if not self._mp4.isOpened():
                    raise TampError(f"cannot write video {self.path}")
            self._mp4.write(bgr)
        self.frames += 1

    def close(self) -> Path | None:
        """Finish the file; returns its path, or None when no frame was written."""
        if self._mp4 is not None:
            self._mp4.release()
            self._mp4 = None
        elif self._gif:
            from PIL import Image

            images = [Image.fromarray(f) for f in self._gif]
            self.path.parent.mkdir(parents=True, exist_ok=True)
            images[0].save(
                self.path, save_all=True, append_images=images[1:], duration=1000 / self.fps,
                loop=0,
            )  # fmt: skip
            self._gif = []
        return self.path if self.frames else None
