"""tamp.api: the library's entry layer, for building on the planner from Python.

One import gives the whole path from a PDDL problem, a scene file or two images to a validated
plan, a closed-loop episode in PyBullet or MuJoCo, or a benchmark table::

    from tamp import api

    task = api.load_problem(api.EXAMPLE)  # PDDL text; a pathlib.Path is read as a file
    planned = api.plan(task)  # an api.PlanReport: status, moves, PDDL actions, validation
    print(planned.text(), planned.validation.reason)
    report = api.run(task, sim="mujoco")  # a tamp.loop.EpisodeReport
    report = api.run("tray", "(in a tray)")  # a scene file's episode: the same report type

Everything in and out is a frozen dataclass (`PddlTask`, `PlanReport`, `PlanningBenchmark` here;
`task.problem.Problem` / `PlanResult`, `task.symbolic.validate.Validation`,
`tamp.loop.EpisodeReport`, `tamp.world.Scene` from the packages), configured by the components'
own ``*Config`` dataclasses (`task.config.PlannerConfig`, `tamp.loop.LoopConfig`,
`tamp.geo.config.GeoEpisodeConfig`), overridden with `dataclasses.replace`. Bad input raises
one line of the `task.errors.TampError` family.

Inputs that may be PDDL are read by one rule: a `pathlib.Path` is a file, a ``str`` is PDDL
text (a plan ``str`` is plan text: ``(unstack a b)`` lines or moves ``move(a -> b)``). Units:
metres, radians and seconds, in the robot base frame (the table surface at z = 0).

Process-wide settings are the caller's: nothing here changes torch's thread count. An episode
is a small problem that runs fastest on one thread, as ``tamp run`` and the benchmarks run it;
wrap a call in ``tamp.sweep.torch_threads(1)`` (or call ``torch.set_num_threads(1)``) to do
the same.

What each function wraps, for reading further: `task.instances` (PDDL in), `task.planner`
(the soft-T_P planner), `task.symbolic.validate` (the crisp validator), `tamp.loop` and
`tamp.geo.episode` (episodes; `tamp.loop.given` for a given plan), `tamp.world` (scene
files), `tamp.camera.image_pair` (planning from two images), `tamp.bench` (benchmarks),
`task.costs` (move costs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from tamp.api.args import (
    BOOL,
    CALLBACK,
    COSTS,
    EPISODE_CONFIG,
    GOAL,
    IMAGE,
    INT,
    INTS,
    LOOP_CONFIG,
    PATH,
    PLAN,
    PLANNER_CONFIG,
    SCENE,
    SOURCE,
    SUITE,
    TEXT,
    TEXTS,
    Kind,
    checked,
)
from tamp.modes import ImageScene
from task import data
from task.config import PlannerConfig
from task.costs import IMPOSSIBLE, CostSource, CostSourceBase, WindowCosts
from task.domains import GENERIC, get_domain, names
from task.domains.match import recognise
from task.errors import PDDLError, TampError, one_of
from task.instances import Instance, from_text
from task.problem import TABLE, Action, Move, PlanResult, PlanStatus, Problem
from task.symbolic import pddl_io
from task.symbolic.validate import Validation, ValidationStatus
from task.symbolic.validate import validate as _validate
from task.symbolic.validate import validate_lines as _validate_lines

if TYPE_CHECKING:  # heavy modules load when a function needs them
    import numpy as np
    from pddl.core import Domain as PDDLDomain
    from torch import Tensor

    from tamp.bench.motion import MotionBench
    from tamp.bench.planning import Bench
    from tamp.bench.suites import Suite
    from tamp.bench.summary import Summary
    from tamp.geo.config import GeoEpisodeConfig
    from tamp.loop import EpisodeReport, LoopConfig
    from tamp.world import Scene

Source = str | Path  # PDDL text (str) or a PDDL file (Path)
PlanSource = str | Path | Sequence[Action | Move]  # plan text, a plan file, or the steps
EXAMPLE = data.read_text(data.EXAMPLE_FILE)  # the embedded 5-block Blocksworld problem (PDDL)
BLOCKSWORLD = data.read_text(data.DOMAIN_FILE)  # the embedded 4-op Blocksworld domain (PDDL)

__all__ = [
    "BLOCKSWORLD",
    "EXAMPLE",
    "IMPOSSIBLE",
    "TABLE",
    "Action",
    "CostFunction",
    "CostSource",
    "CostSourceBase",
    "FixedCosts",
    "Move",
    "PddlTask",
    "PlanReport",
    "PlanResult",
    "PlanStatus",
    "PlannerConfig",
    "PlanningBenchmark",
    "Problem",
    "TampError",
    "Validation",
    "ValidationStatus",
    "WindowCosts",
    "benchmark",
    "benchmark_motion",
    "domain_names",
    "domain_rules",
    "execute_plan",
    "folder_suite",
    "load_problem",
    "load_scene",
    "plan",
    "plan_images",
    "planbench_suite",
    "random_suite",
    "run",
    "validate",
]


# ------------------------------------------------------------------------------- problems


@dataclass(frozen=True)
class PddlTask:
    """A problem read from PDDL: the parsed PDDL ``domain`` (what plans are validated against)
    and the ``instance`` (the planner's `task.problem.Problem`, its parsed PDDL problem, known
    optimal length in PDDL actions or None)."""

    domain: PDDLDomain
    instance: Instance

    @property
    def problem(self) -> Problem:
        """The planner's problem: entities, their initial supports, the goal atoms."""
        return self.instance.problem

    @property
    def name(self) -> str:
        return self.instance.name


def _text(source: Source, what: str) -> tuple[str, str]:
    """``(text, label for errors)`` of PDDL given as text (str) or a file (Path)."""
    if isinstance(source, Path):
        return pddl_io.read_text(source), str(source)
    if not isinstance(source, str):
        raise TampError(
            f"{what}: expected PDDL text (str) or a file (pathlib.Path), got {source!r}"
        )
    if "(define" not in source.lower():
        raise PDDLError(
            f"{what}: {source[:40]!r} is not PDDL text (no '(define'); pass a file as "
            "pathlib.Path(...)"
        )
    return source, f"<{what}>"


def domain_names() -> tuple[str, ...]:
    """The registered soft domain rules (`task.domains`): hand-written domains and ``strips``,
    the generic lift that plans any STRIPS domain."""
    return names()


@checked(domain=SOURCE)
def domain_rules(domain: Source) -> str:
    """The name of the rules that plan a PDDL domain: a hand-written domain it matches
    (``blocksworld``, ``logistics``, ``sokoban``), else ``strips`` (the generic soft lift).
    A domain outside the supported STRIPS fragment fails when a problem of it is loaded."""
    text, label = _text(domain, "domain")
    return recognise(pddl_io.parse_domain(text, label))


@checked(problem=SOURCE, domain=SOURCE.optional(), rules=TEXT.optional())
def load_problem(
    problem: Source, domain: Source | None = None, rules: str | None = None
) -> PddlTask:
    """Read a PDDL problem (text or file) of ``domain`` (text or file; None: the embedded 4-op
    Blocksworld domain, `BLOCKSWORLD`). ``rules`` forces the domain rules (`domain_names`;
    ``strips`` plans a known domain with the generic lift); by default they are recognised."""
    domain_text, domain_label = _text(BLOCKSWORLD if domain is None else domain, "domain")
    parsed = pddl_io.parse_domain(domain_text, domain_label)
    text, label = _text(problem, "problem")
    return PddlTask(parsed, from_text(parsed, text, label, rules=rules))


PROBLEM = Kind(
    "a PddlTask, a Problem, PDDL text (str) or a PDDL file (pathlib.Path)",
    lambda v: isinstance(v, PddlTask | Problem | str | Path),
)  # the problem argument of every function that plans or runs one


def _task(problem: PddlTask | Problem | Source, domain: Source | None = None) -> PddlTask:
    """A `PddlTask` of any problem input; a `Problem` goes through its domain's own PDDL."""
    if isinstance(problem, PddlTask):
        return problem
    if isinstance(problem, Problem):
        rules = get_domain(problem.domain)
        if problem.domain == GENERIC:
            domain_text = rules.pddl_domain_text(problem)
        else:
            domain_text = rules.pddl_domain_text()
        return load_problem(rules.to_pddl(problem), domain_text, problem.domain)
    return load_problem(problem, domain)


# ------------------------------------------------------------------------------- planning


@dataclass(frozen=True)
class PlanReport:
    """A planned problem and its verdict.

    ``result`` is the planner's `PlanResult` with ``validation`` filled in (what
    `task.planner.plan` leaves None): the plan's PDDL ``actions`` replayed by
    `task.symbolic.validate` against the task's own PDDL. A plan the planner did not finish
    (``NO_PLAN``, ``UNSOLVABLE``) validates as ``non_goal_reaching``. ``result.stats`` has
    ``time_s`` (wall seconds) and ``windows`` (receding windows planned)."""

    task: PddlTask
    result: PlanResult
    actions: tuple[Action, ...]

    @property
    def status(self) -> PlanStatus:
        return self.result.status

    @property
    def moves(self) -> tuple[Move, ...]:
        """The plan as the domain's moves (Blocksworld: ``move(a -> b)``)."""
        return self.result.plan.moves

    @property
    def validation(self) -> Validation:
        return self.result.validation

    @property
    def valid(self) -> bool:
        """The plan is executable and reaches the goal, by the crisp validator."""
        return self.result.validation.valid

    def text(self) -> str:
        """The plan file: one ``(action args)`` per line, then ``; cost = N (unit cost)``
        (the VAL / Fast Downward format ``tamp validate`` and ``tamp run --plan`` read)."""
        return pddl_io.format_plan(self.actions)


def _report(task: PddlTask, result: PlanResult) -> PlanReport:
    """``result`` with its validation against ``task``'s PDDL (illegal moves translated as
    they stand, so the validator names the first failing step)."""
    rules = get_domain(task.problem.domain)
    actions = tuple(rules.to_actions(task.problem, result.plan.moves, strict=False))
    verdict = _validate(task.domain, task.instance.pddl, actions)
    return PlanReport(task, replace(result, validation=verdict), actions)


@checked(
    problem=PROBLEM,
    domain=SOURCE.optional(),
    config=PLANNER_CONFIG.optional(),
    seed=INT,
    costs=COSTS.optional(),
)
def plan(
    problem: PddlTask | Problem | Source,
    domain: Source | None = None,
    *,
    config: PlannerConfig | None = None,
    seed: int = 0,
    costs: CostSource | None = None,
) -> PlanReport:
    """Plan one problem with the soft-T_P planner and validate the plan.

    ``problem``: a `PddlTask` (`load_problem`), a `Problem`, or PDDL text / a file of
    ``domain`` (see `load_problem`). ``config``: the planner's settings (None: the defaults
    with the domain's own, `PlannerConfig.for_domain`). ``costs``: move costs in the objective
    (a `CostSource`, e.g. `CostFunction`), weighted by ``config.lambda_motion`` (0.05 when
    ``costs`` is given and ``config`` is None). ``seed`` seeds the restarts' initial logits."""
    from task.planner import plan as soft_plan

    task = _task(problem, domain)
    if config is None:
        weight = {"lambda_motion": 0.05} if costs is not None else {}
        config = PlannerConfig.for_domain(task.problem.domain, **weight)
    return _report(task, soft_plan(task.problem, config, seed, costs=costs))


@checked(problem=PROBLEM, plan=PLAN, domain=SOURCE.optional())
def validate(
    problem: PddlTask | Problem | Source, plan: PlanSource, domain: Source | None = None
) -> Validation:
    """Check a plan from any source against a problem's PDDL: valid, or the first failing step
    and why (``Validation.step``, 1-based; ``reason``; ``failed`` atoms). ``plan``: plan text
    (``str``), a plan file (`pathlib.Path`), or the steps (`Action` or Blocksworld `Move`, or
    their text: ``["(unstack c b)", "(put-down c)"]``)."""
    task = _task(problem, domain)
    if not isinstance(plan, str | Path) and any(isinstance(step, str) for step in plan):
        plan = "\n".join(str(step) for step in plan)  # steps as strings: read as plan text
    if isinstance(plan, str | Path):
        text, label = (
            (pddl_io.read_text(plan), str(plan)) if isinstance(plan, Path) else (plan, "<plan>")
        )
        lines = pddl_io.parse_plan_lines(text, label)
        return _validate_lines(task.domain, task.instance.pddl, lines, label)
    return _validate(task.domain, task.instance.pddl, plan)


# ------------------------------------------------------------------------------- move costs


@dataclass(frozen=True, eq=False)
class FixedCosts:
    """A `WindowCosts` with a constant matrix: ``matrix`` (P, N, Y) is the cost of moving
    entity x onto target y (targets: the entities, then the table) for each of the window's P
    problems; no continuous parameters. Costs at or above `IMPOSSIBLE` rule a move out."""

    matrix: Tensor
    lr: float = 0.0

    def compute(self) -> Tensor:
        return self.matrix  # (P, N, Y)

    def parameters(self) -> list[Tensor]:
        return []

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        return None


@dataclass(frozen=True, eq=False)
class CostFunction(CostSourceBase):
    """A `CostSource` from a function: ``price(problem, state)`` returns the (N, Y) tensor of
    costs of every move from the crisp ``state`` (Blocksworld: a tuple of each entity's support)
    of ``problems[i]``, where ``i`` is the problem's position in the list given to the planner
    (one problem: ``problems=(problem,)``). Every window is priced in its start state; a
    differentiable ``price`` lets gradients flow from the planner's loss into its inputs."""

    price: Callable[[Problem, object], Tensor]
    problems: tuple[Problem, ...]

    def __call__(self, indices: Sequence[int], states: Sequence[object], restarts: int):
        import torch

        rows = [self.price(self.problems[i], s) for i, s in zip(indices, states, strict=True)]
        return FixedCosts(torch.stack(rows))  # (P, N, Y)


# ------------------------------------------------------------------------------- the arm


def _blocksworld(problem: PddlTask | Problem | Source, domain: Source | None) -> Problem:
    """The Blocksworld problem the arm executes; one line for any other domain."""
    loaded = problem if isinstance(problem, Problem) else _task(problem, domain).problem
    if loaded.domain != "blocksworld":
        raise TampError(
            f"{loaded.name}: the arm executes blocksworld problems only; this is a "
            f"{loaded.domain} problem (plan it with tamp.api.plan)"
        )
    return loaded


def _loop_config(config: LoopConfig | None, sim: str | None) -> LoopConfig:
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

    chosen = _loop_config(config, sim)
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
    chosen = _loop_config(config, sim)
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
        chosen = replace(_loop_config(config, sim), scene=task.config)
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


# ------------------------------------------------------------------------------- images


@checked(
    init=IMAGE,
    goal=IMAGE,
    scene=TEXT,
    perception=TEXT,
    checkpoint=PATH.optional(),
    config=PLANNER_CONFIG.optional(),
    seed=INT,
)
def plan_images(
    init: str | Path | np.ndarray,
    goal: str | Path | np.ndarray,
    *,
    scene: str = "cubes",
    perception: str = "frozen",
    checkpoint: str | Path | None = None,
    config: PlannerConfig | None = None,
    seed: int = 0,
) -> PlanReport:
    """Plan from two images (``tamp plan-images``): an initial and a goal scene, PNG/JPG files
    or RGB uint8 arrays (H, W, 3) of the same size. The blocks are the scene's colours found in
    both images (``scene``: ``cubes``, `tamp.scene.PALETTE`; ``latplan``: red, blue, green,
    black), named by colour; the perception model (``checkpoint``; None: the shipped
    ``perception/support.pt``, or ``support-latplan.pt`` for ``latplan``) reads the most likely
    state of each, and the planner plans with ``perception`` ``frozen`` or ``optimised``.
    The plan is validated against the PDDL of the two perceived states."""
    import numpy as np

    from perception import CHECKPOINT
    from perception.perceive import Perceiver
    from perception.train import load_checkpoint
    from tamp.camera.image_pair import (
        blocks_in,
        check_sizes,
        fit_image,
        plan_from_images,
        read_image,
    )
    from task.domains import blocksworld_pddl

    scenes = [s.value for s in ImageScene]
    if scene not in scenes:
        raise TampError(f"unknown image scene {one_of(scene, scenes)}")
    given = {"init": init, "goal": goal}
    pair = [
        fit_image(im, scene) if isinstance(im, np.ndarray) else read_image(im, scene)
        for im in given.values()
    ]
    labels = [f"<{k} image>" if isinstance(im, np.ndarray) else str(im) for k, im in given.items()]
    if checkpoint is None:
        name = "support-latplan.pt" if scene == ImageScene.LATPLAN else CHECKPOINT.name
        checkpoint = CHECKPOINT.with_name(name)
    model, meta = load_checkpoint(checkpoint, scene)
    check_sizes(pair, labels, model)
    names_, colours = blocks_in(pair, labels, scene)
    options = {"input_hw": meta["input_hw"]} if meta.get("input_hw") else {}
    config = PlannerConfig.for_domain("blocksworld") if config is None else config
    perceiver = Perceiver(model, **options, device=config.device)  # read where planning runs
    found = plan_from_images(pair[0], pair[1], colours, names_, perceiver, perception, config, seed)
    domain = pddl_io.parse_domain(BLOCKSWORLD, "<domain>")
    text = blocksworld_pddl.to_pddl(found.problem)
    parsed = pddl_io.parse_problem(text, "<perceived>", domain)
    task = PddlTask(domain, Instance(found.problem.name, found.problem, parsed))
    return _report(task, found.result)


# ------------------------------------------------------------------------------- benchmarks


@dataclass(frozen=True)
class PlanningBenchmark:
    """A planning benchmark's measurements: ``bench`` (every instance's row: status, length,
    optimum, seconds) and ``summary``, the paper's table rows (`tamp.bench.summary.Summary`:
    valid, optimal share, inexecutable, non-goal-reaching, seconds per instance), one per
    horizon and seed, then the mean over seeds."""

    bench: Bench
    summary: tuple[Summary, ...] = field(default=())


@checked(blocks=INTS, n=INT, seed=INT)
def random_suite(blocks: Sequence[int] = (3, 4), n: int = 5, seed: int = 0) -> Suite:
    """``n`` seeded random Blocksworld problems per block count, with optimal lengths from A*
    (``tamp bench random``)."""
    from tamp.bench.suites import generated

    return generated(tuple(blocks), n, seed)


@checked(folder=PATH, limit=INT.optional(), rules=TEXT.optional())
def folder_suite(folder: str | Path, limit: int | None = None, rules: str | None = None) -> Suite:
    """Every problem file of a folder holding ``domain.pddl`` and problems (``tamp bench pddl``);
    ``limit``: a spread of that many; ``rules``: as `load_problem`."""
    from tamp.bench.suites import pddl_folder

    return pddl_folder(folder, limit, rules=rules)


@checked(data_dir=PATH, domain=TEXT, limit=INT.optional())
def planbench_suite(
    data_dir: str | Path, domain: str = "blocksworld", limit: int | None = None
) -> Suite:
    """An official PlanBench set (``blocksworld``: the 600; ``logistics``; ``sokoban``) from a
    checkout laid out as ``../shared/data/planbench/<domain>`` (``tamp bench planbench``);
    ``limit``: a spread of that many instances over the sizes."""
    from tamp.bench.suites import planbench

    return planbench(data_dir, limit, domain=domain)


@checked(suite=SUITE, config=PLANNER_CONFIG.optional(), seeds=INTS, horizons=INTS.optional())
def benchmark(
    suite: Suite,
    config: PlannerConfig | None = None,
    seeds: Sequence[int] = (0,),
    horizons: Sequence[int] | None = None,
) -> PlanningBenchmark:
    """Plan every instance of ``suite`` per horizon and seed in one batched tensor program and
    validate every plan (``tamp bench planbench|pddl|random`` without the printing).
    ``config``: None gives the suite's domain defaults; ``horizons``: the window lengths T
    (default ``config.horizon``)."""
    from tamp.bench import planning, summary
    from tamp.bench.suites import domain_of

    config = PlannerConfig.for_domain(domain_of(suite)) if config is None else config
    bench = planning.run(suite, config, seeds, horizons)
    return PlanningBenchmark(bench, tuple(summary.main_rows(bench)))


@checked(suite=SUITE, sims=TEXTS, config=LOOP_CONFIG.optional(), seed=INT, workers=INT)
def benchmark_motion(
    suite: Suite,
    sims: Sequence[str] = ("pybullet",),
    *,
    config: LoopConfig | None = None,
    seed: int = 0,
    workers: int = 1,
) -> MotionBench:
    """One closed-loop episode per instance in each simulator (``tamp bench motion``): the
    result's ``summary[sim]`` has episodes, goal_reached, moves, moves_ok, failures by kind,
    replans, disturbed stacks, seconds per move; ``reports`` every `EpisodeReport`. Episode k
    uses seed ``seed * 100003 + k``; ``workers`` runs them in that many local processes."""
    from tamp.bench.motion import run

    return run(suite, _loop_config(config, None), tuple(sims), seed, workers=workers)
