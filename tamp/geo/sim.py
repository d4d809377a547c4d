"""A scene file's world in a simulator: `open_sim` builds either backend from a `Scene`.

The entities are the scene's movable objects in the scene's order, each with its own solid
(kind and size) and colour, at its pose; the scene's obstacles and its regions' walls and base
slabs are fixed boxes (`tamp.world.load.scene_config`). The camera is the one given, else the
scene's, else the default `tamp.sim.base.Camera`.
"""

from __future__ import annotations

from tamp.sim.base import SIMULATORS, Camera, Simulator
from tamp.sim.factory import make_simulator
from tamp.world.load import scene_config
from tamp.world.schema import Scene
from task.errors import TampError, one_of


def open_sim(
    scene: Scene,
    backend: str,
    video: bool = False,
    grasp: str = "friction",
    camera: Camera | None = None,
) -> Simulator:
    """The simulator ``backend`` (one of `SIMULATORS`) of ``scene``: its objects as entities,
    at their poses. ``video`` and ``grasp`` ("friction" or "weld") as `Simulator` takes them.
    Close it (or use it as a context manager) when done."""
    if backend not in SIMULATORS:
        raise TampError(f"unknown simulator backend {one_of(backend, SIMULATORS)}")
    view = camera if camera is not None else scene.camera if scene.camera is not None else Camera()
    entities = tuple(o.name for o in scene.objects)
    poses = {o.name: o.pose for o in scene.objects}
    return make_simulator(
        backend,
        entities,
        poses,
        scene_config(scene),
        grasp=grasp,
        camera=view,
        video=video,
    )
