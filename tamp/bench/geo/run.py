"""Run the TAMP benchmark: problems x seeded variants x planners x simulators, one episode each.

Item ``(problem, k, planner, sim)`` plays variant ``seed + k`` of ``problem``
(`tamp.world.canonical.generate`) with ``planner`` in ``sim`` (`run_geo_episode`, episode seed
``seed * 100_003 + k``), so every planner and simulator meets the same scenes and the rows are
the same whatever ``workers`` (`tamp.sweep.run_items`). A row records the variant's note, the
episode's status, whether the goal was reached (ground truth), whether it was reached without a
motion failure, the first plan's length, planning time (s, every planner call of the episode),
simulated execution time, the arm's joint path and the unexpected contacts; with
``observe="camera"`` (the episodes' pose sensor, `tamp.camera.scene_poses.ScenePoses`) also
the camera's pose errors against ground truth over the episode's looks (scored, never acted on):
mean and max position error (mm), max yaw error (deg) and the looks that kept an object's
previous estimate because no camera saw it.

`summarise` gives, per (problem, planner, simulator): episodes, solved, solved without a motion
failure, plan length (median over solved), planning time p50/p90, execution time and arm path
(medians over solved), episodes with a collision and collisions in all; with the camera, the
mean of the episodes' mean position errors, the largest position and yaw errors and the unseen
looks in all.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tamp.geo.types import GeoLimits
from tamp.modes import GeoPlanner, Observation
from tamp.sweep import run_items, torch_threads
from task.errors import TampError, member

# the three, side by side
PLANNERS = (GeoPlanner.SOFT, GeoPlanner.MOTION_AWARE, GeoPlanner.SEARCH_THEN_CHECK)
LIMITS = GeoLimits()  # every episode's limits (`run_geo_episode`): the documented defaults
ROW_COLUMNS = (
    "problem",
    "variant",
    "planner",
    "sim",
    "observe",
    "status",
    "reached_goal",
    "clean",
    "plan_length",
    "moves",
    "motion_failures",
    "replans",
    "collisions",
    "touched",
    "failures",
    "run_notes",
    "plan_time_s",
    "sim_time_s",
    "arm_path_rad",
    "wall_time_s",
    "pose_mm_mean",
    "pose_mm_max",
    "yaw_deg_max",
    "unseen",
    "reason",
    "note",
)


@dataclass(frozen=True)
class Item:
    """One episode to play: variant ``variant`` of ``problem`` by ``planner`` in ``sim``;
    ``video``: a file to record it to (None: no video); ``observe``: the pose sensor.
    ``planner`` and ``observe`` may be given by name."""

    problem: str
    variant: int
    planner: GeoPlanner
    sim: str
    seed: int
    video: str | None = None
    observe: Observation = Observation.STATE

    def __post_init__(self) -> None:
        object.__setattr__(self, "planner", member(GeoPlanner, self.planner, "planner"))
        object.__setattr__(self, "observe", member(Observation, self.observe, "observation"))


def items(
    problems: Sequence[str],
    n: int,
    planners: Sequence[str],
    sims: Sequence[str],
    seed: int,
    videos: Path | None = None,
    observe: str = "state",
) -> list[Item]:
    """Every episode of the benchmark, problem-major; with ``videos``, the first variant of
    each problem gets a video per planner and simulator in that folder; ``observe``: every
    episode's pose sensor (an `Observation`)."""
    out = []
    for problem in problems:
        for k in range(n):
            for planner in planners:
                for sim in sims:
                    video = None
                    if videos is not None and k == 0:
                        video = str(videos / f"{problem}-{planner}-{sim}.mp4")
                    out.append(
                        Item(problem, seed + k, planner, sim, seed * 100_003 + k, video, observe)
                    )
    return out


def play(item: Item) -> dict:
    """One episode's row (`ROW_COLUMNS`), in the process that runs it."""
    from tamp.geo.config import GeoEpisodeConfig
    from tamp.geo.episode import run_geo_episode
    from tamp.world.canonical import generate

    made = generate(item.problem, item.variant)
    t0 = time.perf_counter()
    # ours plans a problem defined by a PDDL domain (Tower of Hanoi) through that domain
    domain = made.domain if item.planner is GeoPlanner.MOTION_AWARE else None
    config = GeoEpisodeConfig(
        planner=item.planner,
        sim=item.sim,
        seed=item.seed,
        limits=LIMITS,
        observation=item.observe,
        video=item.video,
        domain=domain,
    )
    try:
        with torch_threads(1):  # one small problem: thread hand-offs cost more than they give
            report = run_geo_episode(made.scene, made.goal, config)
    except TampError as exc:  # the episode's error is its row; the other episodes go on
        return _error_row(item, made.note, str(exc), time.perf_counter() - t0)
    errors = report.pose_errors
    return {
        "problem": item.problem,
        "variant": item.variant,
        "planner": item.planner.value,
        "sim": item.sim,
        "observe": item.observe.value,
        "status": report.status.value,
        "reached_goal": report.reached_goal,
        "clean": report.reached_goal and report.motion_failures == 0,
        "plan_length": report.plan_length,
        "moves": len(report.moves),
        "motion_failures": report.motion_failures,
        "replans": report.replans,
        "collisions": report.collisions,
        # what was touched (physics steps in contact) and each failed move's failure, in order
        "touched": ";".join(f"{k}:{v}" for k, v in sorted(report.touched.items())),
        "failures": ";".join(_failure(m) for m in report.moves if m.failure),
        # what the run of each move that succeeded had to do beyond the plan (`run_move`'s
        # evidence: regrasped on release, corrected above the place), in order
        "run_notes": ";".join(n for n in (_notes(m) for m in report.moves if m.ok) if n),
        "plan_time_s": report.plan_time_s,
        "sim_time_s": report.sim_time_s,
        "arm_path_rad": report.arm_path_rad,
        "wall_time_s": time.perf_counter() - t0,
        # the camera's estimates against ground truth, over every look (empty: motion capture)
        "pose_mm_mean": errors.get("position_mm_mean"),
        "pose_mm_max": errors.get("position_mm_max"),
        "yaw_deg_max": errors.get("yaw_deg_max"),
        "unseen": ";".join(f"{k}:{v}" for k, v in sorted(errors.get("unseen", {}).items())),
        "reason": report.reason,
        "note": made.note,
    }


def run(
    todo: Sequence[Item],
    workers: int = 1,
    ray_address: str | None = None,
    progress: Callable[[int, dict], None] | None = None,
) -> list[dict]:
    """Every item's row, in item order (``progress(index, row)`` as each episode ends)."""
    return run_items(play, list(todo), workers, ray_address, progress)


def _error_row(item: Item, note: str, why: str, wall: float) -> dict:
    """The row (`ROW_COLUMNS`) of an episode that ended in an error: not reached, nothing
    run, the error as its reason."""
    row = dict.fromkeys(ROW_COLUMNS)
    row |= {"problem": item.problem, "variant": item.variant, "planner": item.planner.value}
    row |= {"sim": item.sim, "observe": item.observe.value, "status": "error", "reason": why}
    row |= {"reached_goal": False, "clean": False, "note": note, "wall_time_s": wall}
    row |= dict.fromkeys(("plan_length", "moves", "motion_failures", "replans", "collisions"), 0)
    row |= dict.fromkeys(("plan_time_s", "sim_time_s", "arm_path_rad"), 0.0)
    row |= {"touched": "", "failures": "", "run_notes": "", "unseen": ""}
    return row


def _median(values: Sequence[float]) -> float | None:
    return float(np.median(values)) if len(values) else None


def _quantile(values: Sequence[float], q: float) -> float | None:
    return float(np.quantile(values, q)) if len(values) else None


def _unseen(rows: Sequence[dict]) -> int:
    """Looks that kept an object's previous estimate, over ``rows``."""
    return sum(int(part.split(":")[1]) for r in rows for part in r["unseen"].split(";") if part)


def camera_summary(rows: Sequence[dict]) -> dict:
    """The camera's pose errors over ``rows`` (episodes observed by the camera): the mean of
    their mean position errors (mm), the largest position (mm) and yaw (deg) errors, and the
    unseen looks; {} when none was."""
    mine = [
        r for r in rows if r.get("observe") == Observation.CAMERA and r["pose_mm_mean"] is not None
    ]
    if not mine:
        return {}
    yaws = [r["yaw_deg_max"] for r in mine if r["yaw_deg_max"] is not None]
    return {
        "pose_mm_mean": float(np.mean([r["pose_mm_mean"] for r in mine])),
        "pose_mm_max": max(r["pose_mm_max"] for r in mine),
        "yaw_deg_max": max(yaws, default=None),
        "unseen_looks": _unseen(mine),
    }


def summarise(rows: Sequence[dict]) -> list[dict]:
    """One summary per (problem, planner, simulator), in the order they first appear."""
    groups: dict[tuple[str, str, str], list[dict]] = {}
    for row in rows:
        groups.setdefault((row["problem"], row["planner"], row["sim"]), []).append(row)
    out = []
    for (problem, planner, sim), mine in groups.items():
        solved = [r for r in mine if r["reached_goal"]]
        times = [r["plan_time_s"] for r in mine if r["status"] != "error"]
        out.append(
            {
                "problem": problem,
                "planner": planner,
                "sim": sim,
                "episodes": len(mine),
                "solved": len(solved),
                "clean": sum(r["clean"] for r in mine),
                "plan_length": _median([r["plan_length"] for r in solved]),
                "moves": _median([r["moves"] for r in solved]),
                "planning_p50_s": _quantile(times, 0.5),
                "planning_p90_s": _quantile(times, 0.9),
                "execution_s": _median([r["sim_time_s"] for r in solved]),
                "arm_path_rad": _median([r["arm_path_rad"] for r in solved]),
                "collided": sum(r["collisions"] > 0 for r in mine),
                "collisions": sum(r["collisions"] for r in mine),
                "statuses": dict(Counter(r["status"] for r in mine)),
                **camera_summary(mine),
            }
        )
    return out


def _failure(record) -> str:
    """A failed move's failure, with where it happened and what it hit when the check or the
    run said so: ``failure[@phase][:other]``."""
    ev = record.evidence or {}
    where = ev.get("phase", ev.get("waypoint", ""))
    out = record.failure.value
    if where:
        out += f"@{where}"
    if ev.get("other"):
        out += f":{ev['other']}"
    return out


NOTES = (
    "regrasped",
    "not_released",
    "corrected_mm",
    "corrected_low_mm",
    "uncorrected_mm",
    "uncorrected_low_mm",
)  # the run evidence kept


def _notes(record) -> str:
    """A successful move's run evidence worth a line (`NOTES`), ``move{key=value,...}``."""
    ev = record.evidence or {}
    kept = [f"{k}={ev[k]}" for k in NOTES if ev.get(k)]
    return f"{record.move}{{{','.join(kept)}}}" if kept else ""
