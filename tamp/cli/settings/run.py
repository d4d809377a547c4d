"""``tamp run`` and ``tamp demo`` at the edge: the parsed options turned once into the typed
settings the command runs with (`RunSettings`), and the recorded configuration built from them.

`run_settings` is the one function of these commands that reads the argparse namespace: it
refuses the option combinations that would do nothing (one line, `TampError`, exit 2), reads the
scene file or lays out the problem, and builds the Blocksworld loop's `tamp.loop.LoopConfig` or
the geometric episode's `tamp.geo.config.GeoEpisodeConfig`. Below it (`tamp.cli.run`) the
command takes these values only; `run_record` is what ``report.json`` and ``--json`` record as
the command's ``config``. Parsing-level only: nothing here plans or simulates.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from tamp.cli.options import check_workcell
from tamp.cli.recorded import PLANNER_FLAGS, flag, loop_config, loop_dict, scene_run
from tamp.rerun_log import check_record_path
from task.errors import TampError


@dataclass(frozen=True)
class RunOutput:
    """Where the episode's artefacts go and how its outcome is shown: ``out``, the folder of the
    video and report.json (None: none written); ``video``, the video's format (``mp4`` or
    ``gif``; None: no video, ``--no-video`` or no ``--out``); ``record``, the Rerun recording
    file (None: none); ``json``, the report on stdout instead of the summary lines."""

    out: str | None = None
    video: str | None = None
    record: str | None = None
    json: bool = False


@dataclass(frozen=True)
class GivenPlan:
    """``--plan PLAN``: the plan file executed open-loop instead of planning (``path`` None:
    plan), ``replan`` after a failed or invalid step, ``stop_at_invalid`` (the experimenter's
    grant)."""

    path: str | None = None
    replan: bool = False
    stop_at_invalid: bool = False


@dataclass(frozen=True)
class Source:
    """What the problem is read from, as typed: ``problem`` (PROBLEM.pddl; None: the embedded
    example), ``domain`` (its domain file, or a bound domain's), ``binding`` (``--binding``),
    ``scene`` (a workcell's name or a scene file) and ``goal`` (the scene file's goal)."""

    problem: str | None = None
    domain: str | None = None
    binding: str | None = None
    scene: str = "tabletop"
    goal: str | None = None


@dataclass(frozen=True)
class RunSettings:
    """Everything ``tamp run`` runs with. ``task``: the scene file's episode or the laid-out
    problem (a `tamp.world.blocks.SceneTask` or a `tamp.geo.scene_file.GeoRun`; None: a PDDL
    problem on a named workcell); exactly one of ``loop`` (the Blocksworld loop's config) and
    ``geo`` (the geometric episode's, for a GeoRun) is set; ``inject``: the faults the
    geometric episode's ``drops`` and ``nudges`` were drawn with (the loop's are ``loop``'s)."""

    source: Source
    seed: int
    output: RunOutput
    given: GivenPlan = GivenPlan()
    task: object | None = None
    loop: object | None = None  # tamp.loop.LoopConfig (imported with torch: not at parse time)
    geo: object | None = None  # tamp.geo.config.GeoEpisodeConfig
    inject: object | None = None  # the geometric episode's tamp.loop.faults.Injection


@dataclass(frozen=True)
class Unsolvable:
    """A scene file's goal the static check (`tamp.world.goal_check`) proved unreachable, found
    at the edge: ``reason``, and what the ``--json`` report names (``scene``, ``goal``)."""

    reason: str
    scene: str
    goal: str | None
    json: bool


def run_settings(args: argparse.Namespace) -> RunSettings | Unsolvable:
    """``run`` and ``demo``: the options as `RunSettings` (or `Unsolvable`), refused
    combinations first, in one line each."""
    from tamp.world.goal_check import UnsolvableGoal

    _refuse_inputs(args)
    source = Source(args.problem, args.domain, args.binding, args.scene, args.goal)
    try:
        task = scene_run(args)
    except UnsolvableGoal as exc:  # before planning: ``unsolvable: REASON``, exit 1
        return Unsolvable(exc.reason, args.scene, args.goal, args.json)
    given = GivenPlan(args.plan, args.replan, args.stop_at_invalid)
    from tamp.geo.scene_file import GeoRun
    from tamp.loop.faults import Injection

    if not isinstance(task, GeoRun):  # the Blocksworld loop
        loop = loop_config(args, task)
        return RunSettings(source, args.seed, _output(args), given, task, loop=loop)
    check_workcell(args, executes=True)  # the geometric episode
    _refuse_for_geo(args, task)
    inject = Injection.parse(args.inject)
    settings = RunSettings(source, args.seed, _output(args), given, task, inject=inject)
    return _with_geo(settings, args)


def _output(args: argparse.Namespace) -> RunOutput:
    """``--out``, ``--no-video``, ``--video-format``, ``--record`` and ``--json`` (the recording
    file's name checked)."""
    return RunOutput(
        out=args.out,
        video=None if args.no_video or args.out is None else args.video_format,
        record=None if args.record is None else str(check_record_path(args.record)),
        json=args.json,
    )


def _refuse_inputs(args: argparse.Namespace) -> None:
    """The combinations of inputs, given plan and video options that would do nothing."""
    binding = args.binding
    if binding is not None and args.domain is None:
        raise TampError("--binding needs --domain DOMAIN.pddl (the domain whose actions it binds)")
    if binding is not None and args.problem is not None:
        raise TampError(
            "--binding with PROBLEM.pddl: a bound domain's problem is read from the scene "
            "file's geometry (--scene FILE.json --goal GOAL)"
        )
    if args.domain is not None and args.problem is None and binding is None:
        raise TampError(
            "--domain needs PROBLEM.pddl (the embedded example has its own domain), or "
            "--scene FILE.json with --binding (a pick-and-place domain bound to the arm)"
        )
    if args.plan is None and (args.replan or args.stop_at_invalid):
        raise TampError("--replan and --stop-at-invalid apply to a given plan (--plan PLAN)")
    if args.no_video and args.video_format != "mp4":
        raise TampError("--video-format with --no-video: there is no video to format")
    if args.out is None and (args.no_video or args.video_format != "mp4"):
        raise TampError("--no-video and --video-format apply with --out DIR (the video's folder)")


GEO_PLANNER_FLAGS = ("time_limit_s",)  # the planner flags a GeoRun reads


def _refuse_for_geo(args: argparse.Namespace, task) -> None:
    """Options of the Blocksworld loop that the geometric episode of ``task`` (a `GeoRun`) has
    no counterpart for, refused in one line: the loop's planner settings (``--time-limit``
    bounds each planner call), ``--device`` other than cpu, ``--placements``, ``--collision``
    other than plan (every phase is checked and blocked ones rerouted), ``--crisp`` and the
    perception network's options; ``--motion-aware`` too (``--geo-planner`` names the planner,
    motion-aware by default)."""
    planner = task.planner
    soft = [
        flag(n)
        for n in PLANNER_FLAGS
        if n not in GEO_PLANNER_FLAGS and getattr(args, n, None) is not None
    ]
    why = []  # (flags, the reason the episode that runs this scene has no use for them)
    if soft:
        why.append(
            (
                soft,
                f"the Blocksworld loop's soft planner's settings; planner {planner} plans "
                "this scene (--geo-planner names it, --time-limit bounds it)",
            )
        )
    if args.device not in (None, "cpu"):
        why.append((["--device"], f"the soft planner's device; planner {planner} runs on the CPU"))
    if args.placements != 0.0:
        why.append(
            (
                ["--placements"],
                "a cost on the loop's table places; planner "
                f"{planner} picks each place by checking its grasp, IK and collisions",
            )
        )
    if args.collision != "plan":
        why.append(
            (
                ["--collision"],
                f"planner {planner} decides each move by its collision checks and the executor "
                "reroutes blocked phases; without them the moves it plans are unchecked",
            )
        )
    seen = [
        name
        for name, value, default in (
            ("--crisp", args.crisp, "perceived"),
            ("--perception", args.perception, "frozen"),
            ("--blur", args.blur, 0),
            ("--checkpoint", args.checkpoint, None),
        )
        if value != default
    ]
    if seen:
        why.append(
            (
                seen,
                "the perception network's, which reads cubes' supports from one image; these "
                "objects are observed as poses (motion capture, or --observe camera's estimates)",
            )
        )
    if why:
        raise TampError(
            "; ".join(f"{', '.join(flags)}: {reason}" for flags, reason in why) + f" ({task.why})"
        )


def _with_geo(settings: RunSettings, args: argparse.Namespace) -> RunSettings:
    """``settings`` with the geometric episode's config: every fault of ``--inject`` (drop,
    nudge, noise) injected as the loop does; the limits not given are the episode's defaults
    (`tamp.geo.types.GeoLimits`), which ``tamp bench tamp`` runs with too."""
    from dataclasses import replace

    import numpy as np

    from tamp.geo.config import GeoEpisodeConfig
    from tamp.geo.search import SearchConfig
    from tamp.geo.types import GeoLimits

    task = settings.task
    defaults = GeoLimits()
    limits = GeoLimits(
        defaults.max_moves,
        defaults.max_replans if args.max_replans is None else args.max_replans,
        defaults.planning_s if args.time_limit_s is None else args.time_limit_s,
    )
    # drop:P: the gripper opens mid-transit on each move with probability P; nudge:P: the
    # object placed is pushed after each move with probability P; both drawn per move index
    # from the seed before the episode (the episode takes the indices); noise:P is drawn by
    # the episode per pose reading
    inject = settings.inject
    rng = np.random.default_rng(args.seed)
    drops = tuple(k for k, u in enumerate(rng.random(limits.max_moves)) if u < inject.drop)
    nudges = tuple(k for k, u in enumerate(rng.random(limits.max_moves)) if u < inject.nudge)
    video = settings.output.video
    config = GeoEpisodeConfig(
        planner=task.planner,
        sim=args.sim,
        seed=args.seed,
        limits=limits,
        search=SearchConfig(seed=args.seed, max_time_s=limits.planning_s),
        observation=args.observe,
        grasp=args.grasp,
        drops=drops,
        nudges=nudges,
        nudge_m=inject.nudge_m,
        noise=inject.noise,
        noise_sigma=inject.noise_sigma,
        video=None if video is None else Path(settings.output.out) / f"episode.{video}",
        domain=task.domain,
    )
    return replace(settings, geo=config)


def run_record(settings: RunSettings | Unsolvable) -> dict:
    """What ``run`` and ``demo`` record as their ``config``: the loop's settings
    (`tamp.cli.recorded.loop_dict`) or the geometric episode's, and the inputs as typed. An
    `Unsolvable` goal has no configuration (`tamp.world.goal_check.UnsolvableGoal`)."""
    if isinstance(settings, Unsolvable):
        from tamp.world.goal_check import UnsolvableGoal

        raise UnsolvableGoal(settings.reason)
    source, output, task = settings.source, settings.output, settings.task
    if settings.geo is not None:
        body = _geo_record(settings)
        if task.workcell is not None:  # a PDDL problem laid out on a workcell
            body |= {"scene_file": None, "problem": source.problem, "scene": task.workcell}
        return body
    return {
        **loop_dict(settings.loop),
        "scene_file": None if task is None else source.scene,
        "goal": None if task is None else task.goal.text(),
        "problem": source.problem,
        "domain": source.domain,
        "seed": settings.seed,
        "plan": settings.given.path,
        "replan": settings.given.replan,
        "stop_at_invalid": settings.given.stop_at_invalid,
        "video": output.video,
        "record": output.record,
    }


def _geo_record(settings: RunSettings) -> dict:
    """The geometric episode's recorded configuration (a `GeoRun`'s)."""
    task, config = settings.task, settings.geo
    return {
        "executor": "geometric",
        "why": task.why,
        "scene_file": task.path,
        "goal": task.goal.text(),
        "planner": task.planner,
        "domain": task.domain_name,
        "domain_file": settings.source.domain,
        "binding": settings.source.binding,
        "sim": config.sim,
        "grasp": config.grasp,
        "observe": config.observation.value,
        "inject": str(settings.inject),
        "max_replans": config.limits.max_replans,
        "max_moves": config.limits.max_moves,
        "time_limit_s": config.limits.planning_s,
        "seed": settings.seed,
        "video": settings.output.video,
        "record": settings.output.record,
    }
