"""Episodes you can scrub through: an episode written as a Rerun recording (``.rrd``).

`RerunRecorder` is an observer that a `tamp.loop.Episode` or a geometric episode
(`tamp.geo.episode.run_geo_episode`) is given (``recorder=``): the episode calls it at its
steps, and it logs what happened on one time line, ``sim``, the simulated time in seconds.
Open a recording with ``rerun FILE.rrd`` (the viewer ships with the extra). Entities:

- ``/world/objects``: the blocks as boxes at their true poses (read under the ground truth's
  ``recording()`` grant, as the video is; the robot never sees this), every frame;
  ``/world/obstacles`` and ``/world/slots`` (static): the scene's fixed boxes and table places;
- ``/camera/image``: the RGB image each camera observation was read from (``observe="camera"``);
- ``/belief/support``: the support matrix of each observation, (N, Y) with rows the blocks and
  columns the support targets: the perceived soft supports F with the camera (columns: the
  blocks by colour, then the table), the observed crisp state one-hot otherwise;
  ``/belief/state``: the same as text, one line per block (a geometric episode: the facts
  read from the observed scene, one per line, `RerunRecorder.facts`);
- ``/plan/moves``: each plan (or camera window) as it is made, a Markdown table of its moves
  (a given plan's steps, `tamp.loop.given`);
  ``/plan/length`` and ``/plan/time_s``: its number of moves (the planner's task cost) and its
  planning time; ``/plan/cost``: each executed move's arm cost (joint path in rad, simulated
  seconds);
- ``/arm/joints``: the measured joint angles (J = 7 series, rad) every frame;
  ``/arm/planned_joints``: the planned trajectory of every phase, at its own times;
  ``/arm/tcp``: the measured TCP position (forward kinematics of the measured joints);
  ``/arm/tcp_path``: each move's TCP path as run; ``/arm/planned_tcp``: each phase's planned
  TCP path, labelled by phase;
- ``/gripper/width`` (m) and ``/gripper/force`` (N, left and right finger) every frame;
- ``/checks/moves``: each move's outcome (ok, or the failure kind and its evidence, with the
  collision checks' time, the phases rerouted and the motion-planner runs), WARN level when it
  failed; ``/checks/failures``: the failed moves so far; ``/checks/contacts``: the unexpected
  contact steps counted so far (contact scoring: the arm or the held block touching what its
  phase does not expect);
- ``/events``: the episode's messages (plans, replans, step lines); ``/episode``: its outcome.

Frames are buffered and sent in columns at each move's end (one batched forward-kinematics call
per move). While recording, the simulator calls back every `FRAME_PERIOD` simulated seconds;
a video made alongside keeps its own frame rate (`tamp.loop.Episode`).

``rerun-sdk`` is an optional extra (``pip install 'soft-tamp[rerun]'``); without it
`require_rerun` (and so `RerunRecorder`) raises a one-line `RecordingError` naming the extra.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from robots.panda import PANDA
from task.errors import TampError

FRAME_PERIOD = 0.05  # simulated seconds between recorded frames
TRAJECTORY_STEP = 0.05  # s: planned trajectories are logged at this spacing
TIMELINE = "sim"
EXTRA = "pip install 'soft-tamp[rerun]'"
SUFFIX = ".rrd"


class RecordingError(TampError):
    """A recording cannot be made: the ``rerun`` extra is missing, or a bad file name."""


def require_rerun():
    """The ``rerun`` module; a one-line `RecordingError` naming the extra when it is missing."""
    try:
        return importlib.import_module("rerun")
    except ImportError:
        raise RecordingError(
            f"--record needs the rerun-sdk package, an optional extra: {EXTRA}"
        ) from None


def check_record_path(path: str | Path) -> Path:
    """``path`` as a recording file: it must end in ``.rrd`` (one-line `RecordingError`)."""
    path = Path(path)
    if path.suffix != SUFFIX:
        raise RecordingError(f"a recording file must end in {SUFFIX}, got {path.name!r}")
    return path


def episode_file(folder: str | Path, sim: str, name: str) -> Path:
    """Where a benchmark's episode of instance ``name`` in ``sim`` is recorded:
    ``folder/recordings/<sim>-<name>.rrd`` (characters other than letters, digits, ``-``, ``_``
    and ``.`` in ``name`` become ``_``)."""
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    return Path(folder) / "recordings" / f"{sim}-{safe}{SUFFIX}"


def recorder_for(folder: str | Path | None, sim: str, name: str) -> RerunRecorder | None:
    """A benchmark episode's recorder (`episode_file` under ``folder``), or None without a
    folder."""
    if folder is None:
        return None
    return RerunRecorder(episode_file(folder, sim, name), name)


def _rgba(rgb: Sequence[float]) -> tuple[int, int, int, int]:
    return (*(round(255 * float(v)) for v in rgb), 255)


class RerunRecorder:
    """Writes one episode to the recording ``path`` (``.rrd``; its folder is made). The
    episode calls `begin` once, `frame` every `period` simulated seconds, `observed`,
    `planned` (or `given`), `phase`, `moved` and `event` as they happen, and `close` with its
    report."""

    period = FRAME_PERIOD

    def __init__(self, path: str | Path, name: str = "episode") -> None:
        rr = require_rerun()
        self.path = check_record_path(path)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RecordingError(f"cannot create {self.path.parent} ({exc})") from None
        self._rr = rr
        self.rec = rr.RecordingStream("soft-tamp", recording_id=f"{name}-{self.path.stem}")
        rr.set_log_time_enabled(False, recording=self.rec)  # one time line: the simulated one
        rr.set_log_tick_enabled(False, recording=self.rec)
        self.rec.save(self.path)
        self.rec.send_recording_name(name)
        self._frames: list[tuple] = []  # (t, q (J,), width, left N, right N, contacts, snapshot)
        self._solver = None
        self._entities: tuple[str, ...] = ()
        self._failures = 0

    # --- what the episode calls ------------------------------------------------------------
    def begin(self, entities: Sequence[str], sim, solver) -> None:
        """The static scene: the movable ``entities`` (a problem's blocks, a scene file's
        objects: their sizes, colours and names), ``sim``'s obstacles and table places, the
        joint names; ``solver`` (`motion.ik.IKSolver`) gives the TCP."""
        rr, rec = self._rr, self.rec
        self._solver = solver
        self._entities = tuple(entities)
        scene = sim.scene
        half = [scene.body(x).half for x in self._entities]
        n = len(self._entities)
        colours = [_rgba(scene.palette[i % len(scene.palette)][1]) for i in range(n)]
        rec.log(
            "world/objects",
            rr.Boxes3D(half_sizes=half, colors=colours, labels=list(self._entities)),
            static=True,
        )
        if scene.obstacles:
            rec.log(
                "world/obstacles",
                rr.Boxes3D(
                    centers=[o.centre for o in scene.obstacles],
                    half_sizes=[o.half for o in scene.obstacles],
                    rotation_axis_angles=[
                        rr.RotationAxisAngle((0, 0, 1), radians=o.yaw) for o in scene.obstacles
                    ],
                    colors=[_rgba(o.rgb) for o in scene.obstacles],
                    labels=[o.name for o in scene.obstacles],
                ),
                static=True,
            )
        slots = [(x, y, 0.0) for x, y in scene.slots]
        rec.log("world/slots", rr.Points3D(slots, radii=0.004), static=True)
        joints = rr.SeriesLines(names=list(PANDA.arm_joints))
        rec.log("arm/joints", joints, static=True)
        rec.log("arm/planned_joints", joints, static=True)
        rec.log("gripper/force", rr.SeriesLines(names=["left", "right"]), static=True)
        rec.log("plan/cost", rr.SeriesLines(names=["arm path (rad)", "sim time (s)"]), static=True)
        self.frame(sim)

    def frame(self, sim) -> None:
        """Buffer what ``sim`` shows now: the measured joints and finger sensors, the contact
        count, and the true block poses (under the ``recording()`` grant)."""
        with sim.truth.recording():
            snapshot = sim.truth.snapshot()
        g = sim.gripper()
        contacts = sum(sim.touched.values())
        row = (sim.time, sim.arm_q().copy(), g.width, g.left_force, g.right_force, contacts)
        self._frames.append((*row, snapshot))

    def observed(self, sim, reading, targets: Sequence[str], image=None, support=None) -> None:
        """An observation at ``sim.time``: ``reading`` (`tamp.scene.Reading`), over the support
        ``targets`` (the problem's); with the camera the ``image`` (H, W, 3) uint8 it came from
        and the perceived soft supports ``support`` F (N, N + 1), else the one-hot of the
        observed state (none when it is unreadable)."""
        rr, rec = self._rr, self.rec
        self.flush()
        self._at(sim.time)
        if image is not None:
            rec.log("camera/image", rr.Image(np.asarray(image)))
        n = len(self._entities)
        if support is not None:
            matrix = np.asarray(support, dtype=np.float32)  # (N, N + 1): by colour, then table
            columns = [f"block {k}" for k in range(n)] + ["table"]
        elif reading.state is not None:
            matrix = np.zeros((n, len(targets)), np.float32)  # (N, Y) one-hot
            for i, y in enumerate(reading.state):
                matrix[i, list(targets).index(y)] = 1.0
            columns = list(targets)
        else:
            rec.log("belief/state", rr.TextDocument("unreadable: " + "; ".join(reading.issues)))
            return
        rec.log("belief/support", rr.Tensor(matrix, dim_names=["block", "support"]))
        lines = []
        for i, row in enumerate(matrix):
            k = int(row.argmax())
            lines.append(f"{self._entities[i]} on {columns[k]} {float(row[k]):.2f}")
        if reading.state is None:
            lines.append("unreadable: " + "; ".join(reading.issues))
        rec.log("belief/state", rr.TextDocument("\n".join(lines)))

    def planned(self, sim, index: int, result) -> None:
        """Plan ``index`` (1-based) made at ``sim.time``: a `task.problem.PlanResult`."""
        head = f"plan {index}: {result.status.value}, {len(result.plan)} moves"
        self.plan_made(sim, head, [str(m) for m in result.plan], result.stats.get("time_s", 0.0))

    def plan_made(self, sim, head: str, moves: Sequence[str], time_s: float) -> None:
        """A plan made at ``sim.time`` in ``time_s`` seconds: its ``moves`` as text under
        ``head`` (a geometric plan's, `tamp.geo.types.GeoMove.text`, or the loop's)."""
        self._plan(sim, head, moves)
        self.rec.log("plan/time_s", self._rr.Scalars(float(time_s)))

    def given(self, sim, labels: Sequence[str]) -> None:
        """A given plan (`tamp.loop.given`): its steps' ``labels``, at ``sim.time``."""
        self._plan(sim, f"given plan: {len(labels)} steps", labels)

    def _plan(self, sim, head: str, moves: Sequence[str]) -> None:
        """``/plan/moves`` (a Markdown table under ``head``) and ``/plan/length``."""
        rr, rec = self._rr, self.rec
        self._at(sim.time)
        rows = [f"| {k} | {m} |" for k, m in enumerate(moves, start=1)]
        table = "| # | move |\n|---|---|\n" + "\n".join(rows)
        rec.log("plan/moves", rr.TextDocument(f"{head}\n\n{table}", media_type="text/markdown"))
        rec.log("plan/length", rr.Scalars(float(len(moves))))

    def phase(self, sim, phase) -> None:
        """A pick-and-place phase (`motion.pick_place.Phase`) about to run from ``sim.time``:
        its planned joints at their own times, and its planned TCP path."""
        rr, rec = self._rr, self.rec
        traj = phase.trajectory
        steps = len(traj.times)
        dt = float(traj.times[1] - traj.times[0]) if steps > 1 else TRAJECTORY_STEP
        every = max(1, round(TRAJECTORY_STEP / dt))  # keep every this many samples, and the last
        keep = np.unique(np.r_[np.arange(0, steps, every), steps - 1])
        times = sim.time + np.asarray(traj.times)[keep]  # (S,)
        q = np.asarray(traj.positions)[keep]  # (S, J)
        rec.send_columns(
            "arm/planned_joints",
            indexes=[rr.TimeColumn(TIMELINE, duration=times)],
            columns=rr.Scalars.columns(scalars=q.ravel()).partition([q.shape[1]] * len(q)),
        )
        if self._solver is not None:
            tcp = self._solver.fk(q)[:, :3, 3]  # (S, 3)
            self._at(sim.time)
            rec.log("arm/planned_tcp", rr.LineStrips3D([tcp], labels=[phase.name], radii=0.002))

    def moved(self, sim, label: str, result) -> None:
        """A move ``label`` ended at ``sim.time`` with ``result`` (`ExecutionResult`)."""
        checks = f"collision checks {result.check_time_s:.2f} s"
        if result.rerouted:
            checks += f", rerouted {', '.join(result.rerouted)}"
        if result.planner_runs:
            checks += f", {result.planner_runs} planner runs ({result.planner_failures} failed)"
        self.outcome(
            sim, label, result.failure, result.evidence, checks, result.path_rad, result.sim_time_s
        )

    def outcome(
        self, sim, label: str, failure, evidence: dict, note: str, path_rad: float, sim_s: float
    ) -> None:
        """A move ``label`` ended at ``sim.time``: ok (``failure`` None) or ``failure`` (a
        `tamp.outcome.Failure`) with ``evidence``; ``note``: what its checks did, after the
        outcome; its arm cost: joint path ``path_rad`` (rad) in ``sim_s`` simulated seconds."""
        rr, rec = self._rr, self.rec
        path = self.flush()
        self._at(sim.time)
        if len(path) > 1:
            rec.log("arm/tcp_path", rr.LineStrips3D([path], labels=[label], radii=0.002))
        tail = f"; {note}" if note else ""
        if failure is None:
            text, level = f"{label}: ok{tail}", "INFO"
        else:
            self._failures += 1
            found = ", ".join(f"{k} {v}" for k, v in evidence.items())
            text, level = f"{label}: {failure.value} ({found}){tail}", "WARN"
        rec.log("checks/moves", rr.TextLog(text, level=level))
        rec.log("checks/failures", rr.Scalars(float(self._failures)))
        rec.log("plan/cost", rr.Scalars([float(path_rad), float(sim_s)]))

    def facts(self, sim, lines: Sequence[str]) -> None:
        """An observation at ``sim.time`` read as facts (a geometric episode's observed scene,
        `tamp.world.relations.read_facts`): ``/belief/state``, one line per fact."""
        self.flush()
        self._at(sim.time)
        self.rec.log("belief/state", self._rr.TextDocument("\n".join(lines)))

    def event(self, sim_time: float, text: str) -> None:
        """A message of the episode at ``sim_time``."""
        self._at(sim_time)
        self.rec.log("events", self._rr.TextLog(text))

    def close(self, report=None) -> None:
        """Send what is buffered, log the episode's outcome (`EpisodeReport`, when it ended
        with one) and finish the file."""
        self.flush()
        if report is not None:
            self._at(report.sim_time_s)
            text = f"{report.problem} in {report.sim}: {report.status.value}"
            text += f" ({report.reason})" if report.reason else ""
            text += f"; goal reached (ground truth): {'yes' if report.reached_goal else 'no'}"
            self.rec.log("episode", self._rr.TextLog(text))
        self.rec.flush()
        self.rec.disconnect()

    # --- helpers ---------------------------------------------------------------------------
    def _at(self, sim_time: float) -> None:
        self.rec.set_time(TIMELINE, duration=float(sim_time))

    def flush(self) -> np.ndarray:
        """Send the buffered frames as columns; returns their TCP positions (F, 3)."""
        if not self._frames:
            return np.zeros((0, 3))
        rr, rec = self._rr, self.rec
        frames, self._frames = self._frames, []
        times = np.array([f[0] for f in frames])  # (F,)
        q = np.stack([f[1] for f in frames])  # (F, J)
        index = [rr.TimeColumn(TIMELINE, duration=times)]
        f = len(frames)
        rec.send_columns(
            "arm/joints",
            indexes=index,
            columns=rr.Scalars.columns(scalars=q.ravel()).partition([q.shape[1]] * f),
        )
        tcp = np.zeros((0, 3))
        if self._solver is not None:
            tcp = self._solver.fk(q)[:, :3, 3]  # (F, 3)
            rec.send_columns("arm/tcp", indexes=index, columns=rr.Points3D.columns(positions=tcp))
        width = np.array([fr[2] for fr in frames])
        rec.send_columns("gripper/width", indexes=index, columns=rr.Scalars.columns(scalars=width))
        force = np.array([[fr[3], fr[4]] for fr in frames])  # (F, 2)
        rec.send_columns(
            "gripper/force",
            indexes=index,
            columns=rr.Scalars.columns(scalars=force.ravel()).partition([2] * f),
        )
        contacts = np.array([float(fr[5]) for fr in frames])
        rec.send_columns(
            "checks/contacts", indexes=index, columns=rr.Scalars.columns(scalars=contacts)
        )
        n = len(self._entities)
        if n:
            centres = np.concatenate([fr[6].centres for fr in frames])  # (F * N, 3)
            wxyz = np.concatenate([fr[6].quats for fr in frames])  # (F * N, 4) w, x, y, z
            xyzw = np.roll(wxyz, -1, axis=1)  # Rerun's quaternions are x, y, z, w
            rec.send_columns(
                "world/objects",
                indexes=index,
                columns=rr.Boxes3D.columns(centers=centres, quaternions=xyzw).partition([n] * f),
            )
        return tcp
