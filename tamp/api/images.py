"""Planning from images in `tamp.api`: `plan_images`, an initial and a goal scene read by the
perception model, planned, and the plan validated against the PDDL of the two perceived
states."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tamp.api.args import IMAGE, INT, PATH, PLANNER_CONFIG, TEXT, checked
from tamp.api.planning import PlanReport, validated_report
from tamp.api.problems import BLOCKSWORLD, PddlTask
from tamp.modes import ImageScene
from task.config import PlannerConfig
from task.errors import TampError, one_of
from task.instances import Instance
from task.symbolic import pddl_io

if TYPE_CHECKING:  # heavy modules load when a function needs them
    import numpy as np


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
    return validated_report(task, found.result)
