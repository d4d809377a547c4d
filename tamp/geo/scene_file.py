"""Which episode runs a scene file: the Blocksworld loop or the geometric TAMP episode.

`scene_episode` resolves what ``tamp run --scene NAME|FILE.json [--goal GOAL] [--geo-planner
P]`` and `tamp.api.run` are given. A scene of 5 cm cubes with ``on`` / ``ontable``
goals is a `tamp.world.blocks.SceneTask` for the closed Blocksworld loop (`tamp.loop`). What the
loop cannot run (`tamp.world.blocks.BeyondLoop`: regions as targets, other shapes, no parking on
the bare table), a canonical problem by its name (`tamp.world.canonical.PROBLEMS`: its shipped
scene, its goal file the default goal) and any scene with a planner named is a `GeoRun` for the
geometric episode (`tamp.geo.episode.run_geo_episode`); so is a Blocksworld PDDL problem
with a planner named (`problem_episode`: laid out on a named workcell). Parsing-level: nothing
here plans, simulates or imports a simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tamp.modes import GeoPlanner
from tamp.world.goal import Goal
from tamp.world.schema import Scene, SceneFileError
from task.problem import Problem

DEFAULT_PLANNER = GeoPlanner.MOTION_AWARE  # ours, where the loop cannot run the scene


@dataclass(frozen=True)
class GeoRun:
    """A scene file for the geometric TAMP episode with ``planner`` (one of
    `tamp.modes.GeoPlanner`). ``why``: why not the loop (the loop's `BeyondLoop` line, a
    canonical problem, or the planner named); ``domain``: the PDDL domain and binding the
    motion-aware planner plans through (the shipped Tower of Hanoi's, as ``tamp bench tamp``
    does), else None."""

    path: str
    scene: Scene
    goal: Goal
    planner: str
    why: str
    domain: tuple[str, str] | None = None
    domain_name: str | None = None  # the PDDL domain ``domain`` plans through
    workcell: str | None = None  # a PDDL problem's: the named workcell it is laid out on


def scene_path(name: str) -> tuple[Path, bool]:
    """The file of scene ``name`` (a shipped scene's or canonical problem's name, or a path)
    and whether it is a canonical problem; SceneFileError when it is none of them."""
    from tamp.world.canonical import PROBLEMS
    from tamp.world.canonical import SCENES_DIR as CANONICAL_DIR
    from tamp.world.load import SCENES_DIR, named_scenes

    if name in PROBLEMS:
        return CANONICAL_DIR / f"{name}.json", True
    path = SCENES_DIR / f"{name}.json" if name in named_scenes() else Path(name)
    if not name.endswith(".json") and not path.is_file():
        raise SceneFileError(
            f"--scene {name}: neither a named scene ({', '.join(named_scenes())}), a canonical "
            f"problem ({', '.join(PROBLEMS)}) nor a scene file (FILE.json)"
        )
    return path, False


def scene_episode(
    name: str | Scene,
    goal: str | Path | None,
    planner: str | None = None,
    rules: tuple[str | Path, str | Path] | None = None,
):
    """The episode of scene ``name`` (or a loaded `Scene`) toward ``goal`` (inline PDDL or a
    file; None: a canonical problem's goal file): a `tamp.world.blocks.SceneTask` when the loop
    can run it and no ``planner`` is named, else a `GeoRun` (``planner`` or
    `DEFAULT_PLANNER`). ``rules``: a user's ``(DOMAIN.pddl, BINDING.json|toml)``, planned
    through by the motion-aware planner (`user_domain`). One-line SceneFileError (or the
    domain's or binding's error) for a scene, goal or domain neither can run (see
    `tamp.world.blocks`)."""
    from tamp.world.blocks import BeyondLoop, scene_task
    from tamp.world.canonical import SCENES_DIR as CANONICAL_DIR

    path, canonical = (name, False) if isinstance(name, Scene) else scene_path(name)
    if isinstance(name, Scene):
        name = name.name  # what the messages name
    if goal is None:
        if not canonical:
            raise SceneFileError(
                f"--scene {name} needs --goal: the goal over the scene file's objects"
            )
        goal = str(CANONICAL_DIR / f"{name}.goal.pddl")
    if rules is not None:
        if planner not in (None, DEFAULT_PLANNER):
            raise SceneFileError(
                f"--geo-planner {planner} with --binding: a user's domain is planned by the "
                f"{DEFAULT_PLANNER} planner (the lift of its PDDL rules)"
            )
        return user_domain(path, goal, *rules)
    why = f"--geo-planner {planner}" if planner is not None else f"{name}: a canonical problem"
    if planner is None and not canonical:
        try:
            return scene_task(path, goal)
        except BeyondLoop as exc:
            why = str(exc)
    return geo_run(path, goal, planner or DEFAULT_PLANNER, why, canonical and name == "hanoi")


def geo_run(path: Path | Scene, goal: str | Path, planner: str, why: str, hanoi: bool) -> GeoRun:
    """The `GeoRun` of the scene file at ``path`` (its geometry must explain every object);
    ``hanoi``: the canonical Tower of Hanoi, which the motion-aware planner plans through its
    PDDL domain."""
    from tamp.world.blocks import explained_scene
    from tamp.world.goal import load_goal
    from tamp.world.goal_check import check_goal

    scene, _ = explained_scene(path)
    domain = None
    if hanoi and planner == DEFAULT_PLANNER:
        from task.symbolic.pickplace import hanoi as rules

        domain = (rules.domain_text(), rules.BINDING)
    name = None if domain is None else rules.DOMAIN
    where = scene.name if isinstance(path, Scene) else str(path)
    return GeoRun(
        where, scene, check_goal(scene, load_goal(goal, scene)), planner, why, domain, name
    )


def problem_episode(
    problem: Problem, workcell: str, planner: str, seed: int, source: str | None = None
) -> GeoRun:
    """The `GeoRun` of a Blocksworld PDDL ``problem`` with ``planner``: the problem laid out on
    the named ``workcell`` with ``seed`` as the loop lays it out
    (`tamp.world.convert.from_problem.problem_scene`), its goal as the scene's (checked by
    `tamp.world.goal_check`: an unreachable goal is `UnsolvableGoal` before any planning).
    ``source``: what messages name (the problem's file; None: the problem's name)."""
    from tamp.world.convert.from_problem import problem_scene
    from tamp.world.goal_check import check_goal

    laid = problem_scene(problem, workcell, seed)
    why = f"--geo-planner {planner}: {problem.name} laid out on workcell {workcell}, seed {seed}"
    return GeoRun(
        source or problem.name,
        laid.scene,
        check_goal(laid.scene, laid.goal),
        planner,
        why,
        workcell=workcell,
    )


def _binding_json(path: Path) -> str:
    """The binding file at ``path`` as JSON text (a TOML file converted), read once; one-line
    BindingError for a wrong suffix, a missing file or bad JSON / TOML."""
    import json

    from task.symbolic.pickplace import binding as binder

    text, fmt = binder.read(path)
    data = binder.decode(text, fmt, str(path))
    return text if fmt == "json" else json.dumps(data)


def user_domain(
    path: Path | Scene, goal: str | Path, domain: str | Path, binding: str | Path
) -> GeoRun:
    """The `GeoRun` of the scene file at ``path`` through a user's pick-and-place PDDL
    ``domain`` and its ``binding`` (`task.symbolic.pickplace.binding`, with a ``scene``
    section: how the geometry reads as the domain's state). Everything is checked here, before
    any planning: the domain, the binding against its actions and predicates, and the problem
    `tamp.world.scene_pddl` writes from the scene and ``goal`` (one line for each)."""
    from tamp.world.blocks import explained_scene
    from tamp.world.goal import load_goal
    from tamp.world.goal_check import check_goal
    from tamp.world.scene_pddl import problem_text
    from task.domains.strips import problem_from_text
    from task.symbolic import pddl_io
    from task.symbolic.pickplace import binding as binder

    scene, _ = explained_scene(path)
    target = check_goal(scene, load_goal(goal, scene))
    domain_text = pddl_io.read_text(domain)
    parsed = pddl_io.parse_domain(domain_text, str(domain))
    binding_text = _binding_json(Path(binding))
    bound = binder.bind_text(binding_text, parsed, source=str(binding))
    problem_from_text(domain_text, problem_text(scene, target, bound), scene.name)
    why = f"--domain {Path(domain).name}: a user's pick-and-place domain ({bound.domain})"
    where = scene.name if isinstance(path, Scene) else str(path)
    return GeoRun(
        where, scene, target, DEFAULT_PLANNER, why, (domain_text, binding_text), bound.domain
    )
