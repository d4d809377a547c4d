"""The perception benchmark (``tamp bench perception``): planning from rendered images.

For each instance the initial state and a goal scene (the PDDL goal completed by
`tamp.camera.states.complete_goal`: blocks the goal leaves free keep their support when
they can) are rendered by a simulator camera. Every (blur, mode, crisp protocol, horizon) row plans
the same instances with the same seed:

- ``state``: ground-truth symbolic states (no images);
- ``frozen`` / ``optimised``: see `tamp.camera.from_images`;
- crisp ``true`` (the paper's: moves checked against the true state) or ``perceived`` (checked
  against the state read from the current image, then applied to the true state, where an
  illegal one makes the plan inexecutable).

Every plan is replayed by the validator against the instance's own PDDL
(`tamp.bench.planning.check`), and "optimal" is `tamp.bench.summary.is_optimal`. Each window's
image is a fresh render of the current true state (new slots, new jitter); a render in which a
block is hidden is redrawn with the next layout seed, and each row counts the images it used that
had to be redrawn. Times per instance exclude rendering (a camera's job) but include
segmentation, the model and planning.
"""

from __future__ import annotations

import time
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from perception.corrupt import Corruption
from perception.errors import PerceptionError
from perception.perceive import Perceiver, blur
from perception.segment import find_boxes
from tamp.bench.planning import STATUSES, check
from tamp.bench.summary import is_optimal
from tamp.camera.from_images import ImageBeliefs, PerceptionMode, perceived_goal
from tamp.camera.render import StateRenderer, block_colours
from tamp.camera.states import complete_goal
from tamp.modes import Crisp, Perception
from task.config import PlannerConfig
from task.errors import TampError
from task.planner import plan_batch

REDRAWS = 8  # layout seeds tried before a render counts as hiding a block
CLEAR = Corruption()  # renders as they are


class Renders:
    """Renders instance images, redrawing layouts that hide a block; keeps time and counts.

    ``redrawn``: redraws in all; ``served[i]``: images of problem i handed out that had to be
    redrawn (a cached goal image counts each time it is handed out)."""

    def __init__(
        self, renderer: StateRenderer, problems, seed: int, corruption: Corruption = CLEAR
    ) -> None:
        self.renderer, self.problems, self.seed = renderer, problems, seed
        self.corruption = corruption  # applied to every render (the stress ladder)
        self.render_s = 0.0
        self.redrawn = 0
        self.served: Counter[int] = Counter()
        self._goals: dict[int, tuple[np.ndarray, bool]] = {}  # every row uses the same goals

    def goal(self, i: int) -> np.ndarray:
        """The goal image of problem i: its completed goal scene, rendered once."""
        if i not in self._goals:
            before = self.redrawn
            image = self._render(i, complete_goal(self.problems[i]), "goal")
            self._goals[i] = image, self.redrawn > before
        image, redrawn = self._goals[i]
        self.served[i] += redrawn
        return image

    def image(self, i: int, state, kind: str = "init") -> np.ndarray:
        """A fresh render of problem i in ``state`` (the same state and kind: the same image)."""
        before = self.redrawn
        image = self._render(i, state, kind)
        self.served[i] += self.redrawn > before
        return image

    def _render(self, i: int, state, kind: str) -> np.ndarray:
        p = self.problems[i]
        key = f"{self.seed}:{i}:{kind}:{','.join(state)}".encode()
        base = zlib.crc32(key)
        t0 = time.perf_counter()
        try:
            for k in range(REDRAWS):
                img = self.renderer.render(p.entities, state, seed=base + k)
                try:
                    boxes = find_boxes(img, block_colours(p.n))
                    return self.corruption(img, base, boxes)
                except PerceptionError:
                    self.redrawn += 1
            return self.corruption(img, base)
        finally:
            self.render_s += time.perf_counter() - t0


@dataclass(frozen=True)
class PerceptionBench:
    """Every row of one perception benchmark: per-instance rows, one summary per (blur, mode,
    horizon), renders redrawn because a block was hidden, and an example image strip."""

    rows: tuple[dict, ...]
    summaries: tuple[dict, ...]
    redrawn: int
    example: np.ndarray


def parse_corruption(text: str) -> Corruption:
    """``noise:8,dim:0.35,occlude`` (any of them, comma-separated) as a `Corruption`."""
    fields: dict = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        name, _, value = part.partition(":")
        try:
            if name == "occlude" and not value:
                fields["occlude"] = True
            elif name in ("noise", "dim"):
                fields[name] = float(value)
            else:
                raise ValueError
        except ValueError:
            raise TampError(
                f"--corrupt: cannot read {part!r} (expected noise:SIGMA, dim:FACTOR, occlude)"
            ) from None
    try:
        return Corruption(**fields)
    except PerceptionError as exc:
        raise TampError(f"--corrupt: {exc}") from None


def parse_modes(text: str) -> tuple[str, ...]:
    """``state,frozen,optimised`` as a tuple; TampError naming an unknown mode."""
    return choices(text, [m.value for m in Perception], "--modes", "mode")


def parse_crisp(text: str) -> tuple[str, ...]:
    """``true,perceived`` as a tuple; TampError naming an unknown crisp protocol."""
    return choices(text, [m.value for m in Crisp], "--crisp", "crisp protocol")


def choices(text: str, valid: Sequence[str], option: str, noun: str) -> tuple[str, ...]:
    """``a,b`` as a tuple of known values; TampError naming an unknown one and the valid ones."""
    chosen = tuple(dict.fromkeys(m.strip() for m in text.split(",") if m.strip()))
    for m in chosen:
        if m not in valid:
            raise TampError(f"{option}: unknown {noun} {m!r}; expected some of {', '.join(valid)}")
    if not chosen:
        raise TampError(f"{option}: expected some of {', '.join(valid)}")
    return chosen


def _goals(problems, mode: PerceptionMode, perceiver, goal_images) -> tuple[list, set[int]]:
    """The goals the planner sees (perceived from goal images unless ``state``), and the
    problems whose goal image hides a block."""
    planned, failed = list(problems), set()
    if mode.mode is Perception.STATE:
        return planned, failed
    for i, p in enumerate(problems):
        try:
            planned[i] = perceived_goal(p, perceiver, goal_images[i], mode.blur)
        except PerceptionError:
            failed.add(i)
    return planned, failed


def _plan(planned, keep, config, seed, beliefs) -> dict:
    """Plan the problems ``keep`` (indices into ``planned``); index -> PlanResult.

    When an image met while planning cannot be read (a block lost in blur, say), the batch is
    planned again one problem at a time, and a problem whose images cannot be read is left
    out (its row says ``perception_error``): one unreadable scene never ends the benchmark."""
    if not keep:
        return {}

    def run(chosen):
        source = None
        if beliefs is not None:

            def source(indices, states):
                return beliefs([chosen[j] for j in indices], states)

        out = plan_batch([planned[i] for i in chosen], config, seed, beliefs=source)
        return dict(zip(chosen, out, strict=True))

    try:
        return run(keep)
    except PerceptionError:
        results = {}
        for i in keep:
            try:
                results.update(run([i]))
            except PerceptionError:
                continue
        return results


@dataclass(frozen=True)
class RowInputs:
    """What every row of one `run` shares: the ``suite`` and its ``chosen`` instances, the
    planner settings, the layout ``seed``, the ``perceiver`` and the ``camera`` (`Renders`)."""

    suite: object
    chosen: Sequence
    config: PlannerConfig
    seed: int
    perceiver: Perceiver
    camera: Renders


def run_row(inputs: RowInputs, mode: PerceptionMode, horizon: int):
    """Plan ``inputs.chosen`` once in one mode; returns per-instance rows and the row
    summary."""
    suite, chosen, seed, camera = inputs.suite, inputs.chosen, inputs.seed, inputs.camera
    perceiver = inputs.perceiver
    config = replace(inputs.config, horizon=horizon)
    problems = [inst.problem for inst in chosen]
    render0, served0, t0 = camera.render_s, Counter(camera.served), time.perf_counter()
    beliefs = goal_images = None
    if mode.mode is not Perception.STATE:
        goal_images = [camera.goal(i) for i in range(len(problems))]
    planned, failed_goal = _goals(problems, mode, perceiver, goal_images)
    if mode.mode is not Perception.STATE:
        beliefs = ImageBeliefs(planned, perceiver, camera.image, goal_images, mode)
    keep = [i for i in range(len(problems)) if i not in failed_goal]
    results = _plan(planned, keep, config, seed, beliefs)
    wall = time.perf_counter() - t0 - (camera.render_s - render0)
    rows = []
    for i, inst in enumerate(chosen):
        r = results.get(i)
        status, length = ("perception_error", None) if r is None else check(suite.domain, inst, r)
        stats = {} if r is None else r.stats
        rows.append(
            {
                "instance": inst.name,
                "blocks": inst.blocks,
                "optimal": inst.optimal,
                "mode": mode.mode.value,
                "crisp": mode.crisp.value,
                "blur": mode.blur,
                "horizon": horizon,
                "status": status,
                "length": length,
                "windows": stats.get("windows"),
                "goal_misread": mode.mode is not Perception.STATE
                and planned[i].goal != _full_goal(problems[i]),
                "misread_windows": stats.get("misread_windows", 0),
                "redrawn": camera.served[i] - served0[i],
                "illegal": stats.get("illegal"),
            }
        )
    valid = [r for r in rows if r["status"] == "valid"]
    optimal = [
        is_optimal(r["length"], r["optimal"], r["instance"])
        for r in valid
        if r["optimal"] is not None
    ]
    summary = {
        "mode": mode.mode.value,
        "crisp": mode.crisp.value,
        "blur": mode.blur,
        "horizon": horizon,
        "n": len(rows),
        "valid": len(valid),
        "optimal": sum(optimal),
        "optimal_pct": 100.0 * sum(optimal) / len(optimal) if optimal else None,
        **{s: sum(r["status"] == s for r in rows) for s in STATUSES if s != "valid"},
        "time_s_per_instance": wall / len(rows),
        "perception_s": 0.0 if beliefs is None else beliefs.perception_s,
        "goal_misread": sum(r["goal_misread"] for r in rows),
        "perception_errors": sum(r["status"] == "perception_error" for r in rows),
        "misread_windows": sum(r["misread_windows"] for r in rows),
        "redrawn": sum(r["redrawn"] for r in rows),
    }
    return rows, summary


def sizes(chosen) -> list[int]:
    """The block counts of ``chosen``, ascending."""
    return sorted({i.blocks for i in chosen})


def _full_goal(problem):
    """The completed goal of ``problem`` as atoms (what a perfect goal reading gives)."""
    return tuple(zip(problem.entities, complete_goal(problem), strict=True))


def run(
    suite,
    modes: Sequence[PerceptionMode],
    horizons: Sequence[int],
    config: PlannerConfig,
    seed: int,
    perceiver: Perceiver,
    sim: str,
    example_blur: int = 0,
    progress: Callable[[PerceptionMode, int], None] | None = None,
    corruption: Corruption = CLEAR,
) -> PerceptionBench:
    """One row per (mode, horizon) in the given order (a mode carries its blur and crisp
    protocol); ``progress(mode, horizon)`` after each.

    The same layout ``seed`` renders the same images for every row, each degraded by
    ``corruption`` (the stress ladder; `perception.corrupt`). The example strip shows the
    first instance's initial and goal images, then both blurred by ``example_blur`` if > 0."""
    chosen = list(suite.instances)
    rows, summaries = [], []
    with StateRenderer(sim) as renderer:
        camera = Renders(renderer, [i.problem for i in chosen], seed, corruption)
        inputs = RowInputs(suite, chosen, config, seed, perceiver, camera)
        for mode in modes:
            for horizon in horizons:
                r, s = run_row(inputs, mode, horizon)
                rows += r
                summaries.append(s)
                if progress is not None:
                    progress(mode, horizon)
        sample = chosen[0].problem
        views = [camera.image(0, sample.init), camera.goal(0)]
        if example_blur:
            views += [blur(im, example_blur) for im in views]
        example = np.hstack(views)  # initial and goal images, then blurred
    return PerceptionBench(tuple(rows), tuple(summaries), camera.redrawn, example)
