"""A scene file of your own: cubes and an obstacle, the state read from geometry, an episode.

A scene file (JSON, schema version 1, documented in `tamp.world.schema`) gives the table, the
slot grid, fixed obstacles and the movable objects with their poses; nobody writes the symbolic
state: `tamp.world.read_facts` reads ``on`` / ``ontable`` / ``clear`` from the geometry, as a
robot would. The episode starts from the file's poses (``tamp run --scene FILE --goal GOAL``).
Units: metres, the robot base frame, the table top at z = 0. Run:
``python examples/custom_scene.py [pybullet|mujoco]`` (about 10 s, headless).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

from tamp import api
from tamp.world import read_facts


def cube(name: str, colour: str, x: float, y: float, level: int) -> dict:
    """A 5 cm cube whose centre stands ``level`` cubes above the table at (x, y)."""
    return {
        "name": name,
        "kind": "cube",
        "size": 0.05,
        "colour": colour,
        "pose": {"xyz": [x, y, 0.025 + 0.05 * level], "yaw": 0.0},
    }


SCENE = {
    "schema": 1,
    "name": "my-bench",
    "table": {"min": [-0.3, -0.7], "max": [1.0, 0.7]},
    "slots": {"xs": [0.4, 0.56], "ys": [-0.32, -0.16, 0.0, 0.16, 0.32]},
    "obstacles": [  # a 20 cm post between the rows, off every slot
        {"name": "post", "centre": [0.48, 0.08, 0.1], "half": [0.015, 0.015, 0.1]}
    ],
    "objects": [
        cube("a", "red", 0.4, -0.16, 0),
        cube("b", "blue", 0.4, -0.16, 1),  # b stands on a
        cube("c", "orange", 0.56, 0.16, 0),
    ],
}
GOAL = "(and (on a b) (on b c))"


def main(sim: str = "pybullet") -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "my-bench.json"
        path.write_text(json.dumps(SCENE, indent=2))
        scene = api.load_scene(path)  # one SceneFileError line naming the field if it is bad
        facts = read_facts(scene)
        print(f"{scene.name}: {len(scene.objects)} objects, {len(scene.obstacles)} obstacle")
        atoms = " ".join(facts.text().splitlines())  # (on b a) (ontable a) ...
        print(f"read from the geometry: {atoms}")
        report = api.run(path, GOAL, sim=sim, seed=0)  # cubes: the Blocksworld loop runs it
    print(f"{sim}: {report.status.value}; goal reached (ground truth): {report.reached_goal}")
    print(f"moves: {', '.join(str(m.move) for m in report.moves)}; touched: {report.touched}")
    assert report.reached_goal


if __name__ == "__main__":
    main(*sys.argv[1:2])
