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

from tamp.api.benchmarks import (
    PlanningBenchmark,
    benchmark,
    benchmark_motion,
    folder_suite,
    planbench_suite,
    random_suite,
)
from tamp.api.costs import CostFunction, FixedCosts
from tamp.api.episodes import execute_plan, load_scene, run
from tamp.api.images import plan_images
from tamp.api.planning import PlanReport, plan, validate
from tamp.api.problems import (
    BLOCKSWORLD,
    EXAMPLE,
    PddlTask,
    domain_names,
    domain_rules,
    load_problem,
)
from task.config import PlannerConfig
from task.costs import IMPOSSIBLE, CostSource, CostSourceBase, WindowCosts
from task.errors import TampError
from task.problem import TABLE, Action, Move, PlanResult, PlanStatus, Problem
from task.symbolic.validate import Validation, ValidationStatus

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
