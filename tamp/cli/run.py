"""``tamp run``: plan a problem, execute it with the simulated Panda, write video and report.
With ``--plan PLAN`` it executes a given plan open-loop instead (`tamp.loop.given`), one line
per step.

Exit code 0 when the episode reaches the goal (scored on simulator ground truth), 1 otherwise
(an empty ``--plan`` file included, as ``tamp validate``). ``tamp demo`` is this command with
``--observe camera --out out/demo``: the camera-to-arm episode ``make demo`` runs.

With ``--scene FILE.json --goal GOAL`` (or a shipped scene's name, e.g. ``--scene tower``) the
problem is the scene file's: its objects start where the file puts them and the initial state
is read from their geometry, never given. A scene of cubes with ``on`` / ``ontable`` goals runs
in the Blocksworld loop (`tamp.world.blocks.scene_task`); one it cannot run (regions as
targets, ``(in c tray)``, other shapes, no parking on the table), a canonical problem by its
name (``--scene packed``, its shipped goal the default) or any scene file with ``--geo-planner``
runs as a geometric TAMP episode (`geo_run`, `tamp.geo.episode.run_geo_episode`): the
motion-aware planner by default, grasps, placements and approaches chosen, each move checked
on the observed scene before it runs. A PDDL problem with ``--geo-planner`` runs there too, laid
out on the workcell ``--scene`` names as the loop would lay it out
(`tamp.world.convert.from_problem`).
"""

from __future__ import annotations

import enum
import json
import math
import sys
import time
from pathlib import Path

from tamp.cli.recorded import checkpoint, load_problem, out_file, out_folder
from tamp.cli.settings.run import RunSettings, Unsolvable, run_record
from tamp.episode_report import EpisodeReport
from tamp.loop import Episode
from tamp.loop.given import GivenPlanEpisode, read_given
from tamp.modes import Observation
from tamp.outcome import EpisodeInterrupted
from tamp.rerun_log import RerunRecorder, require_rerun
from tamp.sweep import torch_threads
from tamp.video import EpisodeVideo
from task.errors import TampError
from task.problem import Problem

VIDEO_FPS = 10.0  # frames per second of playback, each rendered at VIDEO_SIZE (640x480)
SPEEDUP = 4.0  # playback is 4x real time
FRAME_PERIOD = SPEEDUP / VIDEO_FPS  # simulated seconds between video frames
EPISODE_THREADS = 1  # torch threads: one small problem, thread hand-offs cost more than they give


def summary_lines(report: EpisodeReport) -> list[str]:
    moves = report.moves
    ok = sum(r.ok for r in moves)
    per_move = f"{report.wall_time_s / len(moves):.2f} s per move, " if moves else ""
    return [
        *(step.line() for step in report.steps),
        f"{report.problem} in {report.sim}: {report.status.value}"
        f"{' (' + report.reason + ')' if report.reason else ''}; goal reached (ground truth): "
        f"{'yes' if report.reached_goal else 'no'}",
        f"moves {ok}/{len(moves)} ok, {report.replans} replans, faults injected: "
        f"{', '.join(report.faults) or 'none'}",
        f"sim {report.sim_time_s:.1f} s, wall {report.wall_time_s:.1f} s "
        f"({per_move}{report.sim_time_s / max(report.wall_time_s, 1e-9):.1f}x "
        f"real time), planning {report.plan_time_s:.2f} s",
    ]


def _given_steps(path: str | None, problem: Problem):
    """The steps of ``--plan`` (None: plan instead); a plan file without steps is bad input
    (`tamp.loop.given.read_given`: one line, exit 2), as docs/guide/evaluating.md says."""
    if path is None:
        return None
    return read_given(path, problem)


def _out_dir(out: str | None) -> Path | None:
    """``--out`` created (None without it); one line when it cannot be
    (`tamp.bench.results.out_folder`)."""
    from tamp.bench.results import out_folder

    return out_folder(out) if out else None


def run_command(settings: RunSettings | Unsolvable) -> int:
    """Run the episode of ``settings`` (`tamp.cli.settings.run.run_settings`, the options read
    once): its video, report.json and summary; exit 0 when the goal is reached."""
    if isinstance(settings, Unsolvable):  # a scene file's goal no plan can reach
        return unsolvable(settings)
    recorded = run_record(settings)
    output, source, given = settings.output, settings.source, settings.given
    out_folder(output.out)
    out_file(output.record, "--record")
    if output.record is not None:
        require_rerun()  # the optional extra: a one-line error naming it
    task = settings.task
    if settings.geo is not None:
        return geo_run(settings, recorded)
    problem = load_problem(source.problem, source.domain) if task is None else task.problem
    config = settings.loop
    if config.observe == Observation.CAMERA:
        checkpoint(config.checkpoint)
    steps = _given_steps(given.path, problem)
    out = _out_dir(output.out)
    video = None
    if output.video is not None:  # its renderer process starts now
        video = EpisodeVideo(out / f"episode.{output.video}", VIDEO_FPS)
    quiet = output.json

    def say(text: str) -> None:
        if not quiet:
            print(f"  [{time.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)

    recorder = None if output.record is None else RerunRecorder(output.record, problem.name)
    if steps is None:
        poses = None if task is None else dict(task.poses)  # a scene file's: where it puts them
        episode = Episode(
            problem, config, settings.seed, on_event=say, poses=poses, recorder=recorder
        )
    else:
        episode = GivenPlanEpisode(
            problem,
            steps,
            config,
            settings.seed,
            given.replan,
            given.stop_at_invalid,
            on_event=say,
            recorder=recorder,
        )
    if video is not None:

        def frame(sim) -> None:
            caption = f"{sim.name} t={sim.time:5.1f}s  {episode.status_text}"
            video.write(sim, caption, episode.belief_lines())

        episode.on_frame = frame
        episode.sim.frame_period = FRAME_PERIOD
    if not quiet:
        head = f"running {problem.name} ({problem.n} blocks) in {config.sim}, grasp {config.grasp}"
        seen = config.observe
        if seen == Observation.CAMERA:
            seen += f" ({config.perception.mode} perception, blur {config.perception.blur})"
        plan = f", given plan {given.path} ({len(steps)} steps)" if steps is not None else ""
        if task is not None:
            plan += f", scene file {source.scene}, goal {task.goal.text()}"
        print(
            f"{head}, observe {seen}, faults {config.inject}, seed {settings.seed}{plan}",
            file=sys.stderr,
        )
    interrupted = False
    with torch_threads(EPISODE_THREADS):
        try:
            report = episode.run()
        except EpisodeInterrupted as stop:  # Ctrl-C: the video and report of what was done
            report, interrupted = stop.report, True
    written = []
    if video is not None:
        try:
            if video.close() is not None:
                written.append(video.path.name)
        except TampError as exc:  # the episode's outcome and report stand without the video
            print(f"warning: {exc}", file=sys.stderr)
    lines = summary_lines(report)
    _report(report, recorded, out, written, output.json, lines, recorder)
    return _exit_code(report, interrupted)


def unsolvable(found: Unsolvable) -> int:
    """The ``unsolvable`` outcome of a scene file's goal the static check
    (`tamp.world.goal_check`) proved unreachable, as ``tamp plan`` reports a PDDL problem's:
    ``unsolvable: REASON`` (or its ``--json`` report), exit code 1, nothing planned or run."""
    if found.json:
        body = {"status": "unsolvable", "reason": found.reason, "reached_goal": False}
        print(json.dumps({**body, "scene_file": found.scene, "goal": found.goal}, indent=2))
    else:
        print(f"unsolvable: {found.reason}")
    return 1


def geo_run(settings: RunSettings, recorded: dict) -> int:
    """A `tamp.geo.scene_file.GeoRun` (``settings.task``): the geometric episode with
    ``settings.geo``, its video and report.json under ``--out``; exit 0 when the goal is reached
    (ground truth)."""
    from tamp.geo.episode import run_geo_episode

    task, config, output = settings.task, settings.geo, settings.output
    out = _out_dir(output.out)
    video = None if config.video is None else Path(config.video)
    if not output.json:
        print(
            f"running {task.scene.name} ({len(task.scene.objects)} objects) in {config.sim} "
            f"with the geometric episode ({task.why}): planner {task.planner}"
            f"{f' through the {task.domain_name} domain' if task.domain else ''}, "
            f"goal {task.goal.text()}, "
            f"observe {recorded['observe']}, grasp {config.grasp}, faults {recorded['inject']}, "
            f"seed {settings.seed}",
            file=sys.stderr,
        )
    recorder = None if output.record is None else RerunRecorder(output.record, task.scene.name)
    interrupted = False
    with torch_threads(EPISODE_THREADS):
        try:
            report = run_geo_episode(
                task.scene,
                task.goal,
                config,
                on_event=None if output.json else _say,
                recorder=recorder,
            )
        except EpisodeInterrupted as stop:  # Ctrl-C: the video and report of what was done
            report, interrupted = stop.report, True
    written = []
    if video is not None and video.is_file():
        written.append(video.name)
    lines = geo_lines(report)
    _report(report, recorded, out, written, output.json, lines, recorder)
    return _exit_code(report, interrupted)


def _report(
    report: EpisodeReport,
    recorded: dict,
    out: Path | None,
    written: list[str],
    as_json: bool,
    lines: list[str],
    recorder: RerunRecorder | None,
) -> None:
    """The end of either episode's command: ``report.json`` under ``out`` (added to
    ``written``, the files already there), then the report (``--json``) or ``lines``, what was
    written and the Rerun recording's path."""
    body = report_json(report, recorded)
    if out is not None:
        (out / "report.json").write_text(body)
        written.append("report.json")
    if as_json:
        print(body)
    else:
        print("\n".join(lines))
        if written:
            print(f"wrote {', '.join(written)} to {out}")
        if recorder is not None:
            print(
                f"wrote the Rerun recording {recorder.path} (open it with: rerun {recorder.path})"
            )


def _exit_code(report: EpisodeReport, interrupted: bool) -> int:
    """Either episode's exit code: 130 when interrupted, else 0 when the goal is reached, 1
    when not."""
    if interrupted:
        print("tamp: interrupted", file=sys.stderr)
        return 130
    return 0 if report.reached_goal else 1


def _say(text: str) -> None:
    print(f"  [{time.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)


def report_json(report: EpisodeReport, recorded: dict) -> str:
    """``report.json`` of either episode: the report's fields (`EpisodeReport.to_json`, the
    same top-level keys for both) and ``config``, the recorded configuration."""
    body = {**report.to_json(), "config": recorded}
    return json.dumps(_jsonable(body), indent=2, allow_nan=False, default=str)


def geo_lines(report: EpisodeReport) -> list[str]:
    """A geometric episode's `EpisodeReport` as the lines ``tamp run`` prints: one per move,
    then the outcome."""
    lines = []
    for k, m in enumerate(report.moves, 1):
        lines.append(f"  {k:2d}. {m.move}: {'ok' if m.ok else 'FAILED ' + m.failure.value}")
    reason = f" ({report.reason})" if report.reason else ""
    ok = sum(m.ok for m in report.moves)
    return [
        *lines,
        f"{report.status.value}{reason}; goal reached (ground truth): "
        f"{'yes' if report.reached_goal else 'no'}",
        f"moves {ok}/{len(report.moves)} ok, {report.replans} replans, motion failures "
        f"{report.motion_failures}, collisions {report.collisions}",
        f"planning {report.plan_time_s:.2f} s ({len(report.plan_times_s)} calls), sim "
        f"{report.sim_time_s:.1f} s, wall {report.wall_time_s:.1f} s, arm path "
        f"{report.arm_path_rad:.2f} rad",
    ]


def _jsonable(value):
    """``value`` with tuples as lists, numpy scalars as Python numbers and enum members (a
    `tamp.outcome.Failure`, an `EpisodeStatus`) as their values, for json."""
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)  # "inf", "-inf", "nan": json has no such numbers
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if hasattr(value, "item") and callable(value.item):
        return _jsonable(value.item())
    return value
