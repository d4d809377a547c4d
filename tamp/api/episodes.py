"""Episodes in `tamp.api`: `run` (one closed-loop or geometric episode with the simulated
Panda, whatever is given: a PDDL problem, a named workcell or a scene), `execute_plan` (a given
plan executed open-loop at motion level) and `load_scene` (a checked scene file); `loop_config`
is the loop's settings with a simulator override, also what the motion benchmark runs with."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from tamp.api.args import (
    BOOL,
    CALLBACK,
    EPISODE_CONFIG,
    GOAL,
    INT,
    LOOP_CONFIG,
    PATH,
    PLAN,
    SCENE,
    SOURCE,
    TEXT,
    Kind,
    checked,
)
from tamp.api.problems import EXAMPLE, PROBLEM, PddlTask, PlanSource, Source, as_task
from task.errors import TampError, one_of
from task.problem import Problem
from task.symbolic import pddl_io

if TYPE_CHECKING:  # heavy modules load when a function needs them
    from tamp.geo.config import GeoEpisodeConfig
    from tamp.loop import EpisodeReport, LoopConfig
    from tamp.world import Scene


def _blocksworld(problem: PddlTask | Problem | Source, domain: Source | None) -> Problem:
    """The Blocksworld problem the arm executes; one line for any other domain."""
    loaded = problem if isinstance(problem, Problem) else as_task(problem, domain).problem
    if loaded.domain != "blocksworld":
        raise TampError(
            f"{loaded.name}: the arm executes blocksworld problems only; this is a "
            f"{loaded.domain} problem (plan it with tamp.api.plan)"
        )
    return loaded


def loop_config(config: LoopConfig | None, sim: str | None) -> LoopConfig:
    from tamp.loop import LoopConfig

    config = LoopConfig() if config is None else config
    return config if sim is None else replace(config, sim=sim)


def _steps(plan: PlanSource, problem: Problem):
    from tamp.loop.given import parse_given

    if isinstance(plan, Path):
        return parse_given(pddl_io.read_text(plan), str(plan), problem)
    if isinstance(plan, str):
        return parse_given(plan, "<plan>", problem)
    return parse_given("\n".join(str(step) for step in plan), "<plan>", problem)


@checked(
    problem=PROBLEM,
    domain=SOURCE.optional(),
    sim=TEXT.optional(),
    config=LOOP_CONFIG.optional(),
    seed=INT,
    plan=PLAN,
    replan=BOOL,
    stop_at_invalid=BOOL,
)
def execute_plan(
    problem: PddlTask | Problem | Source,
    plan: PlanSource,
    domain: Source | None = None,
    *,
    sim: str | None = None,
    config: LoopConfig | None = None,
    seed: int = 0,
    replan: bool = False,
    stop_at_invalid: bool = False,
) -> EpisodeReport:
    """Execute a plan from any source open-loop at motion level (``tamp run --plan``): 4-op
    PDDL actions (a pick and the put of the same block make one pick-and-place) or moves.
    Every step is attempted, also one invalid at task level, and scored: ``report.steps`` holds
    one `tamp.loop.given.StepReport` per step (task-level verdict, motion outcome, what else
    moved, where the carried block came to rest). ``replan``: the planner takes over after a
    failed or invalid step; ``stop_at_invalid``: the experimenter stops at the first step
    invalid in the true state. ``sim``, ``config`` (a `tamp.loop.LoopConfig`), ``seed``: as
    `run`."""
    from tamp.loop.given import GivenPlanEpisode

    chosen = loop_config(config, sim)
    target = _blocksworld(problem, domain)
    steps = _steps(plan, target)
    episode = GivenPlanEpisode(target, steps, chosen, seed, replan, stop_at_invalid)
    return episode.run()


@checked(scene=SCENE)
def load_scene(scene: str | Path | Mapping) -> Scene:
    """A checked scene file (`tamp.world`): a path to a JSON file (schema version 1), a
    shipped scene's name (``tamp.world.named_scenes()``: tabletop, shelf, clutter, cramped,
    tower, ...) or the file's content as a dict. A bad file raises one
    `tamp.world.SceneFileError` line naming the field."""
    from tamp.world import load_scene

    return load_scene(scene if isinstance(scene, Mapping) else _scene_path(scene))


def _scene_path(scene: str | Path) -> Path:
    """The file of a shipped scene's name, or the path given; a str that is neither an
    existing file nor a shipped scene is one line listing the shipped scenes."""
    from tamp.world import SceneFileError, named_scenes
    from tamp.world.load import SCENES_DIR

    if isinstance(scene, str) and scene in named_scenes():
        return SCENES_DIR / f"{scene}.json"
    if isinstance(scene, str) and not Path(scene).exists():
        raise SceneFileError(
            f"{scene}: no such scene file, nor a shipped scene {one_of(scene, named_scenes())}"
        )
    return Path(scene)


RUNNABLE = Kind(
    "a PddlTask, a Problem, PDDL text (str), a PDDL file (pathlib.Path), a scene file (str or "
    "pathlib.Path), a shipped scene's, workcell's or canonical problem's name (str) or a "
    "tamp.world.Scene",
    lambda v: isinstance(v, PddlTask | Problem | str | Path) or _is_scene(v),
)  # what `run` runs


def _is_scene(value: object) -> bool:
    from tamp.world import Scene

    return isinstance(value, Scene)


def _kind(problem: object) -> str:
    """What ``problem`` is to `run`: ``"pddl"`` (a PddlTask, a Problem, PDDL text or a .pddl
    file), ``"workcell"`` (a named workcell, `tamp.obstacles.SCENES`) or ``"scene"`` (anything
    else: a scene file, a shipped scene's or canonical problem's name, a loaded Scene)."""
    from tamp.obstacles import SCENES as WORKCELLS

    if isinstance(problem, PddlTask | Problem):
        return "pddl"
    if isinstance(problem, Path):
        return "pddl" if problem.suffix.lower() == ".pddl" else "scene"
    if isinstance(problem, str):
        if "(define" in problem.lower():
            return "pddl"
        return "workcell" if problem in WORKCELLS else "scene"
    return "scene"


@checked(
    problem=RUNNABLE,
    goal=GOAL.optional(),
    config=EPISODE_CONFIG.optional(),
    domain=SOURCE.optional(),
    binding=PATH.optional(),
    sim=TEXT.optional(),
    seed=INT.optional(),
    on_event=CALLBACK.optional(),
)
def run(
    problem: PddlTask | Problem | Source | Scene,
    goal: str | Path | None = None,
    config: LoopConfig | GeoEpisodeConfig | None = None,
    *,
    domain: Source | None = None,
    binding: str | Path | None = None,
    sim: str | None = None,
    seed: int | None = None,
    on_event: Callable[[str], None] | None = None,
) -> EpisodeReport:
    """One episode with the simulated Panda, headless, whatever is given
    (``tamp run``); the `EpisodeReport` both episodes return (``reached_goal`` scored on
    simulator ground truth, ``planner`` and ``sim`` recorded, times in seconds).

    ``problem`` is one of:

    - a Blocksworld problem: a `PddlTask`, a `Problem`, PDDL text or a ``.pddl`` file (of
      ``domain``; None: the embedded 4-op domain). It runs in the closed Blocksworld loop
      (`tamp.loop`): the blocks (5 cm cubes) laid out on table slots with ``seed``, then
      observe, plan a window, execute each move as a pick-and-place, check, and replan on a
      failure, until the goal or a stop. With a `GeoEpisodeConfig` the same layout is a scene
      on the ``tabletop`` workcell (`tamp.world.convert.from_problem`) and runs as a
      geometric episode with the config's planner (``tamp run PROBLEM.pddl --geo-planner
      P``);
    - a named workcell (`tamp.obstacles.SCENES`: ``tabletop``, ``shelf``, ``clutter``,
      ``cramped``): the embedded example (`EXAMPLE`) in the loop among its obstacles (``tamp
      run --scene shelf``), or laid out there for the geometric episode with a
      `GeoEpisodeConfig`;
    - a scene: a scene file (str or Path), a shipped scene's name (``tower``, ``tray``), a
      canonical problem's (``packed``, its goal file the default ``goal``) or a loaded
      `tamp.world.Scene`, toward ``goal`` (a PDDL goal over its objects, inline or a file:
      ``(and (on a b) (on b c))``, ``(in a tray)``). A scene of cubes with ``on`` /
      ``ontable`` goals runs in the loop from the file's poses; any other (regions as targets,
      other shapes, a canonical problem), or any scene with a `GeoEpisodeConfig`, runs as a
      geometric TAMP episode (`tamp.geo.episode`: grasps and placements chosen, each move
      checked before it runs) with the config's planner (ours, ``motion-aware``, by default).
      ``domain`` and ``binding``: your own pick-and-place PDDL domain and its binding file
      (``tamp run --domain D.pddl --binding B.json``), planned through by the motion-aware
      planner.

    ``config``: a `tamp.loop.LoopConfig` for the loop (observation, grasp, faults, planner,
    workcell) or a `tamp.geo.config.GeoEpisodeConfig` for the geometric episode (planner,
    limits, observation, grasp, video); None: the defaults of the episode that runs.
    ``sim`` (``pybullet`` or ``mujoco``) and ``seed`` override the config's (None: the
    config's; the loop's seed is 0 by default). ``on_event(text)``: progress lines."""
    kind = _kind(problem)
    if kind == "scene":
        return _run_scene(problem, goal, config, domain, binding, sim, seed, on_event)
    from tamp.loop import Episode

    what = "a workcell" if kind == "workcell" else "a PDDL problem"
    if goal is not None or binding is not None:
        given = "goal" if goal is not None else "binding"
        raise TampError(
            f"api.run: {given} is for a scene file (the objects it names); {what} has its own goal"
        )
    if _is_geo(config):  # laid out on the workcell as a scene: the geometric episode
        return _run_laid_out(problem, kind, domain, config, sim, seed, on_event)
    chosen = loop_config(config, sim)
    if kind == "workcell":
        from tamp.world import load_named, scene_config

        chosen = replace(chosen, scene=scene_config(load_named(problem)))
        target = _blocksworld(EXAMPLE, domain)
    else:
        target = _blocksworld(problem, domain)
    return Episode(target, chosen, seed or 0, on_event=on_event).run()


def _is_geo(config: object) -> bool:
    from tamp.geo.config import GeoEpisodeConfig

    return isinstance(config, GeoEpisodeConfig)


def _run_laid_out(problem, kind, domain, config, sim, seed, on_event) -> EpisodeReport:
    """`run` of a Blocksworld problem (a workcell: the embedded example on it) with a
    `GeoEpisodeConfig`: the problem laid out on the workcell (``tabletop`` for a problem) with
    ``seed`` (None: the config's) as the loop lays it out, run by the config's planner."""
    from tamp.geo.episode import run_geo_episode
    from tamp.geo.scene_file import problem_episode

    workcell, source = (problem, EXAMPLE) if kind == "workcell" else ("tabletop", problem)
    chosen = config if seed is None else replace(config, seed=seed)
    if sim is not None:
        chosen = replace(chosen, sim=sim)
    target = _blocksworld(source, domain)
    task = problem_episode(target, workcell, chosen.planner, chosen.seed)
    return run_geo_episode(task.scene, task.goal, chosen, on_event=on_event)


def _run_scene(scene, goal, config, domain, binding, sim, seed, on_event) -> EpisodeReport:
    """`run` of a scene: the loop's `SceneTask` or the geometric episode's `GeoRun`."""
    from tamp.geo.config import GeoEpisodeConfig
    from tamp.geo.episode import run_geo_episode
    from tamp.geo.scene_file import GeoRun, scene_episode
    from tamp.loop import Episode

    if (domain is None) != (binding is None):
        raise TampError("api.run: domain and binding go together (a bound domain)")
    geo = isinstance(config, GeoEpisodeConfig)
    rules = None if domain is None else (domain, binding)
    name = scene if _is_scene(scene) else str(scene)
    task = scene_episode(name, goal, config.planner if geo else None, rules)
    if not isinstance(task, GeoRun):  # a scene of cubes: the Blocksworld loop
        chosen = replace(loop_config(config, sim), scene=task.config)
        poses = dict(task.poses)
        return Episode(task.problem, chosen, seed or 0, poses=poses, on_event=on_event).run()
    if config is not None and not geo:
        raise TampError(
            f"api.run: {task.path} runs as a geometric episode ({task.why}): config must be a "
            f"tamp.geo.config.GeoEpisodeConfig, got {type(config).__name__}"
        )
    chosen = replace(config or GeoEpisodeConfig(), planner=task.planner, domain=task.domain)
    if sim is not None:
        chosen = replace(chosen, sim=sim)
    if seed is not None:
        chosen = replace(chosen, seed=seed)
    return run_geo_episode(task.scene, task.goal, chosen, on_event=on_event)
