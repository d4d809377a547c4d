"""The simulator's ground truth behind one door, `GroundTruth`, which the closed loop locks.

Simulator ground truth only scores episodes: a real robot has joint encoders, finger sensors
and a camera, not the world's state. Every ground-truth query (block poses, which the one
state reader `tamp.world.convert.from_poses.read_state` reads as the true symbolic state; the
snapshot a video frame is drawn from) goes through ``sim.truth``. An episode locks it; a
locked `GroundTruth` answers only inside one of four named grants, and anything else that reads
it raises `GroundTruthLeak` naming the caller:

- ``scoring()``: the experimenter scores the episode (the goal check, disturbed stacks, a given
  plan's per-step verdicts); what it reads never changes what the robot does;
- ``experimenter()``: the experimenter's own interventions, which do change the episode: fault
  injection reads what it perturbs (the nudged block's pose), and a given plan run with
  ``stop_at_invalid`` has the experimenter, not the robot, skip a step invalid in the true state;
- ``oracle()``: the motion-capture pose sensor of ``observe="state"``, whose documented sensor
  is exactly the true block poses (plus optional noise);
- ``recording()``: a video of the episode for people to watch (`tamp.video`), drawn from
  ``snapshot()``; nothing it reads flows back into the episode.

``reads`` counts every answered read by grant and calling function, so a test can check that a
camera episode read nothing but scoring. Teleports (``Simulator.set_block_pose``) write the
world and are not reads.
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import NamedTuple

import numpy as np

from tamp.scene import Pose
from task.errors import TampError

GRANTS = ("scoring", "experimenter", "oracle", "recording")
RULE = "simulator ground truth only scores episodes"


class Snapshot(NamedTuple):
    """What a video frame shows (`GroundTruth.snapshot`, `tamp.sim.base.Simulator.show`), in
    any backend: arm and finger joint positions (J + 2,), block centres (N, 3) and orientations
    (N, 4) as quaternions (w, x, y, z), blocks in ``entities`` order."""

    joints: np.ndarray
    centres: np.ndarray
    quats: np.ndarray


class GroundTruthLeak(TampError):
    """Robot-side code read the simulator's ground truth while it was locked."""


def _caller() -> str:
    """The first function on the stack outside this module and contextlib, as module.qualname."""
    frame = sys._getframe(1)
    while frame is not None and frame.f_globals.get("__name__") in (__name__, "contextlib"):
        frame = frame.f_back
    if frame is None:
        return "<unknown>"
    return f"{frame.f_globals.get('__name__', '?')}.{frame.f_code.co_qualname}"


class GroundTruth:
    """Ground-truth queries of one simulator; ``read_poses`` gives the true block poses and
    ``read_snapshot`` the arm and the true block poses as a video frame shows them.

    Unlocked (the default: tests, renderers, dataset builders), every read is answered.
    Locked, only reads inside ``scoring()``, ``experimenter()``, ``oracle()`` or
    ``recording()`` are.
    """

    def __init__(
        self,
        read_poses: Callable[[], dict[str, Pose]],
        read_snapshot: Callable[[], Snapshot] | None = None,
    ) -> None:
        self._read_poses = read_poses
        self._read_snapshot = read_snapshot
        self.locked = False
        self._grants: list[str] = []
        self.reads: Counter[tuple[str, str]] = Counter()  # (grant or "unlocked", caller) -> n

    def lock(self) -> None:
        """From now on, answer only reads inside a named grant."""
        self.locked = True

    def unlock(self) -> None:
        self.locked = False

    @contextmanager
    def scoring(self) -> Iterator[GroundTruth]:
        """Reads to score the episode (goal reached, disturbed stacks)."""
        with self._grant("scoring"):
            yield self

    @contextmanager
    def experimenter(self) -> Iterator[GroundTruth]:
        """Reads by the experimenter's interventions, not by the robot: fault injection (what
        it perturbs) and ``stop_at_invalid`` (whether a given step is attempted at all)."""
        with self._grant("experimenter"):
            yield self

    @contextmanager
    def oracle(self) -> Iterator[GroundTruth]:
        """Reads by the motion-capture oracle of ``observe="state"`` (its sensor is the truth)."""
        with self._grant("oracle"):
            yield self

    @contextmanager
    def recording(self) -> Iterator[GroundTruth]:
        """Reads by an episode's video (`tamp.video`): snapshots for people to watch."""
        with self._grant("recording"):
            yield self

    @contextmanager
    def _grant(self, name: str) -> Iterator[None]:
        self._grants.append(name)
        try:
            yield
        finally:
            self._grants.pop()

    def purposes(self) -> set[str]:
        """The grants under which reads were answered ("unlocked" for reads while unlocked)."""
        return {grant for grant, _ in self.reads}

    def block_poses(self) -> dict[str, Pose]:
        """The true block poses (centre, yaw); raises `GroundTruthLeak` outside a grant when
        locked."""
        self._check("block_poses")
        return self._read_poses()

    def snapshot(self) -> Snapshot:
        """The arm, fingers and true block poses now (`Snapshot`), what a video
        frame shows; raises `GroundTruthLeak` outside a grant when locked."""
        self._check("snapshot")
        if self._read_snapshot is None:
            raise TampError("this ground truth has no snapshots (it was made from poses only)")
        return self._read_snapshot()

    def _check(self, query: str) -> None:
        caller = _caller()
        if self.locked and not self._grants:
            raise GroundTruthLeak(
                f"{caller} read the ground truth ({query}) while it is locked: {RULE}. "
                f"Robot-side code observes with its sensors; only reads inside "
                f"{', '.join(f'GroundTruth.{g}()' for g in GRANTS)} are answered"
            )
        self.reads[(self._grants[-1] if self._grants else "unlocked", caller)] += 1
