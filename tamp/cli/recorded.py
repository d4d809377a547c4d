"""What each ``tamp`` command records as its configuration, and the checks run before any work.

Every command's handler builds the settings it runs with through the function named here for it
(the parser binds it as ``args.recorded``; ``run``, ``demo``, ``plan``, ``example`` and
``validate`` build theirs at the edge instead, `tamp.cli.settings`), and writes that dict as
the ``config`` of its ``results.json`` / ``report.json`` / ``--json`` output. So an option
either changes the recorded config (and the run, which is built from the same objects) or is
refused here in one line
(`TampError`, exit 2) in the combination where it would do nothing; ``tests/tamp/cli/
test_every_option.py`` walks every option of every command to keep it so.

Also here: the output checks (`out_file`, `out_folder`), done before the work so a long run is
never lost to a path that cannot be written, and the checkpoint check (`checkpoint`).
Parsing-level only: nothing here plans, simulates or imports a simulator.
"""

from __future__ import annotations

import argparse
from dataclasses import asdict, replace
from pathlib import Path

from perception import CHECKPOINT
from tamp.cli.options import SCENES, check_workcell, planner_config
from tamp.cli.types import sim_list
from tamp.modes import ImageScene, Observation
from task import data
from task.errors import TampError
from task.instances import example, from_files, from_text
from task.problem import Problem
from task.symbolic import pddl_io

# options that change where or how the output is shown, never what is computed: checked by
# their own tests (tests/tamp/cli/test_every_option.py names them)
PRESENTATION = frozenset({"json", "out", "progress", "help"})


def _planner(args: argparse.Namespace, domain: str | None = None) -> dict:
    return asdict(planner_config(args, domain))


def images_config(args: argparse.Namespace) -> dict:
    """``plan-images``."""
    return {
        **_planner(args, "blocksworld"),
        "seed": args.seed,
        "image_scene": args.image_scene,
        "perception": args.perception,
        "checkpoint": args.checkpoint,
        "threads": args.threads,
    }


def loop_config(args: argparse.Namespace, task=None):
    """The `LoopConfig` of ``run``, ``demo`` and ``bench motion`` (refused combinations first);
    ``task``: the scene file's `tamp.world.blocks.SceneTask` (`scene_run`, read once by the
    caller: a scene file of hundreds of objects takes seconds to load and check), whose table
    it runs on (None: the named workcell ``--scene``). The loop plans with Blocksworld's
    planner defaults, as ``tamp plan`` does."""
    from tamp.camera.from_images import PerceptionMode
    from tamp.loop import LoopConfig
    from tamp.loop.execute import ExecConfig
    from tamp.loop.faults import Injection
    from tamp.world import load_named, scene_config
    from task.domains.blocksworld import NAME as BLOCKSWORLD

    check_workcell(args, executes=True)
    config = LoopConfig(
        sim=args.sim,
        grasp=args.grasp,
        planner=planner_config(args, BLOCKSWORLD),  # the loop's problems (`LoopConfig.planner`)
        inject=Injection.parse(args.inject),
        observe=args.observe,
        perception=PerceptionMode(args.perception, blur=args.blur),
        checkpoint=args.checkpoint,
        crisp=args.crisp,
        scene=scene_config(load_named(args.scene)) if task is None else task.config,
        execution=replace(ExecConfig(), collision=args.collision),
        placements=args.placements,
    )
    if args.max_replans is not None:
        config = replace(config, max_replans=args.max_replans)
    return config


def scene_run(args: argparse.Namespace):
    """``run`` and ``demo`` with ``--scene FILE.json [--goal GOAL]``: the scene file's episode
    (`tamp.geo.scene_file.scene_episode`: a `tamp.world.blocks.SceneTask` for the Blocksworld
    loop or a `tamp.geo.scene_file.GeoRun` for the geometric episode), None with a named
    workcell; with a workcell and ``--geo-planner``, the GeoRun of the PDDL problem laid out
    on it (`_problem_run`). Refused in one line before any work: ``--goal`` without a scene
    file or with a PDDL problem, a scene file or ``--geo-planner`` with ``--plan``, the loop's
    scene file with the camera, and what `scene_episode` refuses."""
    goal = getattr(args, "goal", None)
    name = getattr(args, "scene", "tabletop")
    geo = getattr(args, "geo_planner", None)
    if goal is not None and getattr(args, "problem", None) is not None:
        raise TampError("--goal with PROBLEM.pddl: the goal is the scene file's or the problem's")
    if name in SCENES:
        if goal is not None:
            raise TampError(
                f"--goal needs --scene FILE.json (the objects it names); --scene {name} is a "
                "named workcell, whose problem is PROBLEM.pddl"
            )
        if getattr(args, "binding", None) is not None:
            raise TampError(
                f"--binding needs --scene FILE.json (the objects its domain moves); --scene "
                f"{name} is a named workcell"
            )
        if geo is not None:  # the PDDL problem laid out on the workcell, any planner
            return _problem_run(args, name, geo)
        return None
    if getattr(args, "problem", None) is not None:
        raise TampError(
            f"PROBLEM.pddl with --scene {name}: a scene file's problem is read from its geometry"
        )
    from tamp.geo.scene_file import GeoRun, scene_episode

    binding = getattr(args, "binding", None)
    rules = None if binding is None else (args.domain, binding)
    task = scene_episode(name, goal, geo, rules)
    if getattr(args, "plan", None) is not None:
        raise TampError(
            "--plan with a scene file: the plan reader reads PDDL actions and moves between "
            "blocks, not a scene's moves to checked places and grasps (yet); use PROBLEM.pddl"
        )
    if not isinstance(task, GeoRun) and getattr(args, "observe", "state") == Observation.CAMERA:
        raise TampError(
            "--observe camera with a Blocksworld scene file: the camera's goal image is "
            "laid out from a PDDL problem (yet); use --observe state, or --geo-planner "
            "(the geometric episode's cameras estimate the objects' poses)"
        )
    return task


def load_problem(problem: str | None, domain: str | None) -> Problem:
    """The problem file (with ``domain`` or the embedded 4-op domain), or the embedded example."""
    if problem is None:
        return example()[1].problem
    if domain is None:
        loaded = from_text(data.domain(), pddl_io.read_text(problem), str(problem)).problem
    else:
        loaded = from_files(domain, problem)[1].problem
    if loaded.domain != "blocksworld":
        raise TampError(
            f"{problem}: the arm executes blocksworld problems only; this is a "
            f"{loaded.domain} problem (plan it with 'tamp plan')"
        )
    return loaded


def _problem_run(args: argparse.Namespace, workcell: str, planner: str):
    """``run PROBLEM.pddl --geo-planner P`` (the embedded example without PROBLEM.pddl): a
    `tamp.geo.scene_file.GeoRun` of the problem laid out on ``workcell`` with ``--seed``."""
    from tamp.geo.scene_file import problem_episode

    if getattr(args, "plan", None) is not None:
        raise TampError(
            f"--plan with --geo-planner {planner}: a given plan runs in the Blocksworld loop "
            "(leave out --geo-planner)"
        )
    problem = load_problem(getattr(args, "problem", None), getattr(args, "domain", None))
    source = getattr(args, "problem", None) or f"the example {problem.name}"
    return problem_episode(problem, workcell, planner, args.seed, source)


def loop_dict(config) -> dict:
    """A `LoopConfig` as recorded (flat names kept from earlier reports)."""
    return {
        "sim": config.sim,
        "grasp": config.grasp,
        "inject": str(config.inject),
        "max_replans": config.max_replans,
        "observe": config.observe,
        "perception": config.perception.mode,
        "blur": config.perception.blur,
        "checkpoint": config.checkpoint,
        "crisp": config.crisp,
        "scene": config.scene.name,
        "collision": config.execution.collision,
        "lambda_motion": config.planner.lambda_motion,
        "placements": config.placements,
        "planner": asdict(config.planner),
    }


def given_config(args: argparse.Namespace):
    """The loop settings of ``bench executability``: grasp, scene, collision mode, and the
    planner and placements of our reference row (refused without it)."""
    from tamp.loop import LoopConfig
    from tamp.loop.execute import ExecConfig
    from tamp.obstacles import with_scene
    from tamp.scene import SceneConfig

    check_workcell(args, executes=True)
    if not args.ours:
        given = [name for name in PLANNER_FLAGS if getattr(args, name, None) is not None]
        if given:
            flags = ", ".join(flag(n) for n in given)
            raise TampError(
                f"{flags} set(s) our planner, whose row --no-ours leaves out; drop one of them"
            )
    return LoopConfig(
        grasp=args.grasp,
        scene=with_scene(SceneConfig(), args.scene),
        execution=replace(ExecConfig(), collision=args.collision),
        planner=planner_config(args, "blocksworld"),
        placements=args.placements,
    )


def flag(dest: str) -> str:
    """The option of a `PLANNER_FLAGS` destination as the user types it."""
    return _FLAG_NAMES.get(dest, "--" + dest.replace("_", "-"))


# the planner options whose names are not their destinations (`tamp.cli.options`)
_FLAG_NAMES = {
    "lambda_motion": "--motion-aware",
    "time_limit_s": "--time-limit",
    "improve_s": "--improve",
}

PLANNER_FLAGS = (
    "horizon",
    "restarts",
    "iters",
    "goal_loss",
    "lookahead_share",
    "lookahead",
    "max_windows",
    "park_free",
    "improve_s",
    "time_limit_s",
    "tau_end",
    "lambda_motion",
)


def executability_config(args: argparse.Namespace) -> dict:
    """``bench executability``."""
    config = given_config(args)
    records_under_out(args.record, args.out)
    return {
        "plans": str(args.plans),
        "sims": list(sim_list(args.sim)),
        "n": args.n,
        "seed": args.seed,
        "grasp": config.grasp,
        "ours": args.ours,
        "data": str(args.data),
        "scene": config.scene.name,
        "collision": config.execution.collision,
        "lambda_motion": config.planner.lambda_motion if args.ours else None,
        "placements": config.placements,
        "planner": asdict(config.planner) if args.ours else None,
        "threads": args.threads,
        "workers": args.workers,
        "ray": args.ray,
        "record": args.record,
    }


def records_under_out(record: bool, out: str | None) -> None:
    """A benchmark's ``--record`` writes OUT/recordings/: refused without ``--out``."""
    if record and not out:
        raise TampError("--record writes OUT/recordings/SIM-INSTANCE.rrd; give --out DIR")


def tamp_bench_config(args: argparse.Namespace) -> dict:
    """``bench tamp``."""
    if args.video and not args.out:
        raise TampError("--video writes under --out; give --out DIR")
    return {
        "problems": list(args.problems),
        "n": args.n,
        "seed": args.seed,
        "planners": list(args.planners),
        "sims": list(sim_list(args.sim)),
        "video": args.video,
        "observe": args.observe,
        "workers": args.workers,
        "ray": args.ray,
    }


def planning_config(args: argparse.Namespace, domain: str | None = None) -> dict:
    """``bench planbench``, ``bench pddl`` and ``bench random``: the planner config the suite
    runs with (``domain``: its rules' defaults) and the suite's own options."""
    config = planner_config(args, domain)
    peers = getattr(args, "peers", None)
    if peers and config.time_limit_s is None:
        raise TampError("--peers needs --time-limit SECONDS: the same limit for every planner")
    if getattr(args, "one_at_a_time", False) or peers:
        config = replace(config, batched=False)
    body = {
        **asdict(config),
        "horizons": list(args.horizons or (config.horizon,)),
        "seeds": args.seeds,
        "sequential": args.sequential,
        "threads": args.threads,
    }
    for name in ("data", "limit", "domain", "domain_rules", "blocks", "n", "seed", "max_nodes"):
        if hasattr(args, name):
            value = getattr(args, name)
            body[f"suite_{name}"] = list(value) if isinstance(value, tuple) else value
    if hasattr(args, "lama"):
        body["lama"] = args.lama
    if hasattr(args, "baselines"):
        if args.baselines and getattr(args, "domain", "blocksworld") != "blocksworld":
            raise TampError(f"--baselines plan Blocksworld only, not --domain {args.domain}")
        body["baselines"] = list(args.baselines) if args.baselines else None
    if hasattr(args, "peers"):
        body["peers"] = list(peers) if peers else None
    return body


def perception_bench_config(args: argparse.Namespace) -> dict:
    """``bench perception``."""
    return {
        **_planner(args),
        "horizons": list(args.horizons or (planner_config(args).horizon,)),
        "data": str(args.data),
        "n": args.n,
        "modes": args.modes,
        "blur": list(args.blur),
        "crisp": args.crisp,
        "corrupt": args.corrupt,
        "sim": args.sim,
        "checkpoint": str(args.checkpoint),
        "kl_weight": args.kl_weight,
        "adapt": args.adapt,
        "seed": args.seed,
        "threads": args.threads,
    }


def latplan_config(args: argparse.Namespace) -> dict:
    """``bench latplan``."""
    images = any(m.strip() != "state" for m in args.modes.split(","))
    if not images and Path(args.checkpoint) != CHECKPOINT.with_name("support-latplan.pt"):
        raise TampError("--checkpoint with --modes state: no image is read; drop one")
    return {
        "config": _planner(args, "blocksworld"),
        "data": str(args.data),
        "checkpoint": str(args.checkpoint) if images else None,
        "resolutions": args.res,
        "modes": args.modes,
        "seeds": args.seeds,
        "limit": args.limit,
        "threads": args.threads,
    }


def poses_config(args: argparse.Namespace) -> dict:
    """``bench poses``."""
    if args.min_blocks > args.max_blocks:
        raise TampError(
            f"--min-blocks {args.min_blocks} is more than --max-blocks {args.max_blocks}"
        )
    return {
        "sims": list(sim_list(args.sim)),
        "n": args.n,
        "seed": args.seed,
        "blocks": [args.min_blocks, args.max_blocks],
        "jitter": args.jitter,
    }


def segmentation_config(args: argparse.Namespace) -> dict:
    """``bench segmentation``: the datasets and the checkpoint it reads; refused in one line,
    before any work, when one of them is not a file or a dataset is given twice."""
    missing = [str(p) for p in (*args.data, args.checkpoint) if not Path(p).is_file()]
    if missing:
        raise TampError(
            f"no such file: {', '.join(missing)} (datasets come from `tamp perception dataset`, "
            "checkpoints from `tamp perception train`)"
        )
    twice = sorted({str(p) for p in args.data if args.data.count(p) > 1})
    if twice:
        raise TampError(f"dataset(s) given twice: {', '.join(twice)}; give each file once")
    return {
        "data": [str(p) for p in args.data],
        "checkpoint": str(args.checkpoint),
        "device": args.device,
    }


def dataset_config(args: argparse.Namespace) -> dict:
    """``perception dataset``."""
    if args.image_scene == ImageScene.LATPLAN and (args.min_blocks, args.max_blocks) != (3, 6):
        raise TampError("--min-blocks/--max-blocks with --image-scene latplan: it has 4 blocks")
    if args.min_blocks > args.max_blocks:
        raise TampError(
            f"--min-blocks {args.min_blocks} is more than --max-blocks {args.max_blocks}"
        )
    return {
        "n": args.n,
        "seed": args.seed,
        "sims": list(sim_list(args.sim)),
        "image_scene": args.image_scene,
        "blocks": None
        if args.image_scene == ImageScene.LATPLAN
        else [args.min_blocks, args.max_blocks],
    }


def train_config(args: argparse.Namespace) -> dict:
    """``perception train``."""
    return {
        "train": args.train,
        "test": args.test,
        "epochs": args.epochs,
        "seed": args.seed,
        "threads": args.threads,
        "device": args.device,
    }


def eval_config(args: argparse.Namespace) -> dict:
    """``perception eval``."""
    return {
        "data": args.data,
        "checkpoint": str(args.checkpoint),
        "blur": args.blur,
        "device": args.device,
    }


# --- checks before the work ------------------------------------------------------------------
def out_file(path: str | None, option: str = "--out") -> None:
    """``path`` can be written as a file: not a folder, its folder created and written to for
    a try, and left as it was (TampError)."""
    if path is None:
        return
    target = Path(path)
    if target.is_dir():
        raise TampError(f"{option} {target}: is a folder; give a file name")
    parent = target.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise TampError(f"{option} {target}: {parent} is a file, not a folder")
    _probe(target, option)


def out_folder(path: str | None, option: str = "--out") -> None:
    """``path`` is or can become a folder (TampError before any work)."""
    if path is None:
        return
    target = Path(path)
    if target.exists() and not target.is_dir():
        raise TampError(f"{option} {target}: is a file; give a folder")
    out_file(str(target / "results.json"), option)


def _probe(target: Path, option: str) -> None:
    """Create ``target``'s missing folders and a file in its folder, then remove what was made
    (TampError when either fails): a permission check alone says yes to root anywhere, also
    under /proc, where nothing can be created, and the work was lost at the end."""
    import contextlib
    import tempfile

    missing = [p for p in target.parents if not p.exists()][::-1]  # outermost first
    made = []
    try:
        for folder in missing:
            folder.mkdir()
            made.append(folder)
        with tempfile.TemporaryFile(dir=target.parent):
            pass
    except OSError as exc:
        why = exc.strerror or exc
        raise TampError(f"{option} {target}: cannot be created or written ({why})") from None
    finally:
        for folder in reversed(made):
            with contextlib.suppress(OSError):
                folder.rmdir()


def checkpoint(path: str | Path | None) -> None:
    """A perception checkpoint that loads, or one `TampError` line naming it: torch's errors
    for a file that is not a checkpoint (several lines) become one."""
    if path is None:
        return
    import pickle
    import zipfile

    from perception.train import load_checkpoint

    if not Path(path).is_file():
        raise TampError(f"--checkpoint {path}: no perception checkpoint there (no such file)")
    try:
        load_checkpoint(path)
    except TampError:
        raise
    except (
        pickle.UnpicklingError,
        zipfile.BadZipFile,
        EOFError,
        RuntimeError,
        ValueError,
        KeyError,
        TypeError,
        AttributeError,
        OSError,
    ) as exc:
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise TampError(f"--checkpoint {path}: not a perception checkpoint ({first})") from None
