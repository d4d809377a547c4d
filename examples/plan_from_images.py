"""Plan from two images: a photograph of the scene now and one of the goal scene.

The images here are PyBullet renders (any camera or renderer works: PNG or JPG, the same size).
The blocks are the cube palette's colours found in both images and are named by colour; the
shipped perception model (``perception/support.pt``, trained by the project's own
``tamp perception dataset`` / ``tamp perception train`` commands recorded in its meta) reads
the most likely state of each image, and the planner plans from those soft states. The plan
is validated against the PDDL of the two perceived states. Same as
``tamp plan-images INIT.png GOAL.png``. Run: ``python examples/plan_from_images.py``
(about 10 s, headless).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import cv2

from tamp import api
from tamp.camera.render import StateRenderer

BLOCKS = ("red", "blue", "orange")  # palette colours 0, 1, 2
NOW = ("table", "red", "table")  # blue on red, orange alone
GOAL = ("blue", "table", "red")  # red on blue, orange on red


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp, StateRenderer("pybullet") as camera:
        paths = []
        for name, state, seed in (("now", NOW, 1), ("goal", GOAL, 2)):
            rgb = camera.render(BLOCKS, state, seed=seed)  # (240, 320, 3) uint8
            path = Path(tmp) / f"{name}.png"
            cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
            paths.append(path)
        planned = api.plan_images(paths[0], paths[1], perception="frozen", seed=0)
    problem = planned.task.problem
    print(f"blocks seen: {', '.join(problem.entities)}")
    print(f"perceived now: {dict(zip(problem.entities, problem.init, strict=True))}")
    print(f"perceived goal: {dict(problem.goal)}")
    print(planned.text(), end="")
    print(f"{planned.status.value}: {planned.validation.reason}")
    assert planned.valid
    assert dict(problem.goal) == dict(zip(BLOCKS, GOAL, strict=True))


if __name__ == "__main__":
    main()
