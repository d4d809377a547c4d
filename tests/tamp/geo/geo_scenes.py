"""Small scenes the geometric TAMP tests share, and one set of `Tools` per test process (the
IK solver and the collision model take seconds to build)."""

from __future__ import annotations

import atexit
import functools

from tamp.world.load import load_scene
from tamp.world.schema import Scene

GOAL = {"name": "goal", "min": [0.40, -0.32], "max": [0.60, -0.16]}  # room for six cubes


def cube(name: str, x: float, y: float, z: float = 0.025, size: float = 0.05, yaw: float = 0.0):
    return {
        "name": name,
        "kind": "cube",
        "size": size,
        "colour": "red",
        "pose": {"xyz": [x, y, z], "yaw": yaw},
    }


def scene(*objects, regions=(GOAL,), obstacles=(), slots=None) -> Scene:
    data = {
        "schema": 1,
        "name": "geo-test",
        "table": {"min": [-0.3, -0.7], "max": [1.0, 0.7]},
        "regions": list(regions),
        "obstacles": list(obstacles),
        "objects": list(objects),
    }
    if slots is not None:
        data["slots"] = slots
    return load_scene(data)


DESK = {"name": "desk", "min": [0.35, -0.30], "max": [0.65, 0.30]}  # a marked area
ALCOVE = {"name": "alcove", "min": [0.465, 0.115], "max": [0.535, 0.185]}  # in it: one cube


def alcove(*objects, inner_first: bool) -> Scene:
    """Region ``alcove`` (room for one cube) marked inside region ``desk``, listed first when
    ``inner_first``; no parking, so an object goes into a region or onto an object."""
    regions = [ALCOVE, DESK] if inner_first else [DESK, ALCOVE]
    data = {
        "schema": 1,
        "name": "alcove-test",
        "table": {"min": [-0.3, -0.7], "max": [1.0, 0.7]},
        "regions": regions,
        "objects": list(objects),
        "parking": False,
    }
    return load_scene(data)


def blocked() -> Scene:
    """Target ``t`` hemmed in 1 cm apart by ``w`` (-x), ``e`` (+x) and ``n`` (+y): no grasp
    reaches it until ``n`` (or ``w`` and ``e``) moves; region ``goal`` beside them."""
    return scene(
        cube("t", 0.5, 0.0), cube("w", 0.44, 0.0), cube("e", 0.56, 0.0), cube("n", 0.5, 0.06)
    )


def hemmed() -> Scene:
    """Target ``t`` with ``w`` on its -x side and ``n`` on its +y side, 1 cm apart: every
    top-down grasp of t has a finger on w or n until one of them moves."""
    return scene(cube("t", 0.5, 0.0), cube("w", 0.44, 0.0), cube("n", 0.5, 0.06))


@functools.cache
def tools():
    """One `tamp.geo.check.Tools` for the whole test process, closed at exit (torch on one
    thread: small IK batches on a shared machine)."""
    import torch

    from tamp.geo.check import Tools

    torch.set_num_threads(1)

    made = Tools()
    atexit.register(made.close)
    return made
