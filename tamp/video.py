"""Episode videos: camera frames with a caption, streamed to MP4 (OpenCV) or GIF (Pillow).

`VideoWriter` writes the frames it is given as they come, so a long episode never holds its
video in memory. `EpisodeVideo` records an episode off its physics loop's critical path: a frame
is a `tamp.sim.truth.Snapshot` of the world (joint positions and block poses, a few hundred
bytes, read through the simulator's ground truth under its ``recording()`` grant) sent to a
spawned process, which poses its own copy of the world (``video=True``),
renders it at `VIDEO_SIZE` with ``render_video`` and writes it. The episode's simulator, and so
every camera image perception sees, is untouched.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import signal
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import cv2
import numpy as np

from tamp.scene import Pose, SceneConfig
from tamp.sim.base import VIDEO_SIZE, Camera, Lighting, Simulator
from task.errors import TampError

FORMATS = (".mp4", ".gif")
TEXT_WIDTH = 320  # frames this wide get the caption's base size; wider ones scale it up


def _check_format(path: Path) -> None:
    if path.suffix not in FORMATS:
        raise TampError(f"video file must end in one of {FORMATS}, got {path.name!r}")


class VideoWriter:
    """``write(rgb, caption)`` appends a frame (H, W, 3) uint8; ``close()`` finishes the file."""

    def __init__(self, path: str | Path, fps: float = 20.0) -> None:
        self.path = Path(path)
        _check_format(self.path)
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
        h, w = bgr.shape[:2]
        s = max(1.0, w / TEXT_WIDTH)  # text scale

        def text(line: str, x: float, y: float, size: float) -> None:
            at = (round(x * s), round(y * s))
            cv2.putText(
                bgr, line, at, cv2.FONT_HERSHEY_SIMPLEX, size * s, (255, 255, 255), 1, cv2.LINE_AA
            )

        if caption:
            cv2.rectangle(bgr, (0, 0), (w, round(18 * s)), (0, 0, 0), -1)
            text(caption, 4, 13, 0.4)
        for k, line in enumerate(reversed(list(notes))):
            y = h / s - 6 - 13 * k
            corners = (0, round((y - 10) * s)), (round((8 + 6 * len(line)) * s), round((y + 3) * s))
            cv2.rectangle(bgr, *corners, (0, 0, 0), -1)
            text(line, 4, y, 0.35)
        if self.path.suffix == ".gif":
            self._gif.append(bgr[..., ::-1].copy())
        else:
            if self._mp4 is None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
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
                self.path,
                save_all=True,
                append_images=images[1:],
                duration=1000 / self.fps,
                loop=0,
            )
            self._gif = []
        return self.path if self.frames else None


class _World(NamedTuple):
    """What the renderer process needs to build its copy of the episode's world."""

    sim: str
    entities: tuple[str, ...]
    poses: dict[str, Pose]
    scene: SceneConfig
    camera: Camera
    lighting: Lighting


class EpisodeVideo:
    """An episode's video, rendered at ``size`` (W, H) in a process of its own.

    ``write(sim, caption, notes)`` queues what ``sim`` shows now (the camera and light as they
    are at the first frame); ``close()`` waits for the renderer to finish the file and returns
    its path, or None when no frame was written. The renderer's output (the EGL plugin's
    chatter) goes to /dev/null; its errors come back as a `TampError` from ``close()``.
    """

    def __init__(self, path: str | Path, fps: float = 20.0, size: tuple[int, int] = VIDEO_SIZE):
        self.path = Path(path)
        _check_format(self.path)
        self.frames = 0
        context = multiprocessing.get_context("spawn")  # fork would copy torch's and a sim's state
        self._frames, self._result = context.Queue(), context.Queue()
        self._frames.cancel_join_thread()  # exiting never waits on a dead renderer's pipe
        args = (self.path, fps, size, self._frames, self._result)
        self._process = context.Process(target=_render, args=args, daemon=True)
        self._process.start()  # its imports overlap the episode's start

    def write(self, sim: Simulator, caption: str = "", notes: Sequence[str] = ()) -> None:
        """Queue what ``sim`` shows now: its snapshot (the true block poses), read under the
        ground truth's ``recording()`` grant, which an episode's lock answers."""
        with sim.truth.recording():
            snapshot = sim.truth.snapshot()
        if self.frames == 0:
            centres = zip(sim.entities, snapshot.centres, strict=True)
            poses = {n: Pose(tuple(float(v) for v in c)) for n, c in centres}
            world = _World(sim.name, sim.entities, poses, sim.scene, sim.camera, sim.lighting)
            self._frames.put(world)
        self._frames.put((snapshot, caption, tuple(notes)))
        self.frames += 1

    def close(self) -> Path | None:
        self._frames.put(None)
        while True:
            try:
                outcome = self._result.get(timeout=1.0)
                break
            except queue.Empty:
                if not self._process.is_alive():
                    outcome = f"its renderer process died (exit code {self._process.exitcode})"
                    break
        self._process.join()
        if isinstance(outcome, str):
            raise TampError(f"cannot write video {self.path}: {outcome}")
        return self.path if outcome else None


def _next(frames):
    """The next message; ends the renderer when the episode's process is gone (killed)."""
    while True:
        try:
            return frames.get(timeout=1.0)
        except queue.Empty:
            if not multiprocessing.parent_process().is_alive():
                raise SystemExit(1) from None


def _render(path: Path, fps: float, size: tuple[int, int], frames, result) -> None:
    """The renderer process: a world from the first message, then one frame per message until
    None; puts the number of frames written, or an error message, on ``result``. It ignores
    Ctrl-C (the terminal sends it to the whole process group): the episode's process stops
    and closes the video, whose frames so far this process then finishes into a playable
    file."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the episode's: it closes the file
    quiet = os.open(os.devnull, os.O_WRONLY)
    os.dup2(quiet, 1)  # stdout belongs to the episode (--json); the EGL plugin prints on it
    os.dup2(quiet, 2)
    os.environ.setdefault("LP_NUM_THREADS", "1")  # Mesa's llvmpipe: one core, the episode the other
    from tamp.sim.factory import make_simulator

    sim = None
    try:
        writer = VideoWriter(path, fps)
        world = _next(frames)
        if world is not None:
            sim = make_simulator(
                world.sim, world.entities, world.poses, world.scene, camera=world.camera, video=True
            )
            sim.set_view(world.camera, world.lighting)
            while (frame := _next(frames)) is not None:
                snapshot, caption, notes = frame
                sim.show(snapshot)
                writer.write(sim.render_video(size), caption, notes)
        writer.close()
        result.put(writer.frames)
    except Exception as exc:  # any failure goes back to close()
        result.put(f"{type(exc).__name__}: {exc}")
    finally:
        if sim is not None:
            sim.close()
