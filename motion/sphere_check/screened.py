"""A mesh collision model with the batched sphere model beside it, screening for the search.

`Screened` answers every query of the mesh model (e.g. `robots.collision.PandaCollision`, the
final word) from it, and ``valid_batch`` from a `motion.sphere_check.collision.SphereCollision`
that mirrors its scene: conservative, so the motion planner (`motion.rrt.plan_path`) searches
with the spheres and the guard checks what it finds with the meshes.
"""

from __future__ import annotations

from collections.abc import Sequence

from motion.sphere_check.collision import Ignore, SphereCollision
from robots.collision import Box
from robots.panda import PANDA


class Screened:
    """A mesh collision model (e.g. `robots.collision.PandaCollision`) with a `SphereCollision`
    beside it that mirrors its scene: ``set_boxes``, ``hold`` and ``margin`` go to both;
    ``valid``, ``contacts`` and ``check_path`` are the mesh model's (the final word);
    ``valid_batch`` is the spheres' (conservative: False wherever the mesh model would find a
    contact, and sometimes where it would not), for `motion.rrt.plan_path`'s ``valid_batch``.
    """

    def __init__(self, mesh, spheres: SphereCollision | None = None):
        self.mesh = mesh
        self.spheres = spheres if spheres is not None else SphereCollision(mesh.margin)
        self.spheres.margin, self.spheres.self_margin = mesh.margin, mesh.self_margin

    @property
    def margin(self) -> float:
        return self.mesh.margin

    @margin.setter
    def margin(self, value: float) -> None:
        self.mesh.margin = self.spheres.margin = value

    def set_boxes(self, boxes: Sequence[Box]) -> None:
        self.mesh.set_boxes(boxes)
        self.spheres.set_boxes(boxes)

    def hold(self, size: float | None = None, half=None, pose=None) -> None:
        self.mesh.hold(size, half, pose)
        self.spheres.hold(size, half, pose)

    def valid(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()) -> bool:
        return self.mesh.valid(q, fingers, ignore)

    def contacts(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()):
        return self.mesh.contacts(q, fingers, ignore)

    def check_path(self, path, fingers=PANDA.finger_open, ignore: Ignore = (), max_step=0.02):
        return self.mesh.check_path(path, fingers, ignore, max_step)

    def valid_batch(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()):
        return self.spheres.valid_batch(q, fingers, ignore)

    def __getattr__(self, name: str):
        """Anything else (``parts``, ``spec``, ``close``, ...) is the mesh model's."""
        if name in ("mesh", "spheres"):  # not set yet: no recursion through the mesh
            raise AttributeError(name)
        return getattr(self.mesh, name)

    def __enter__(self) -> Screened:
        return self

    def __exit__(self, *exc) -> None:
        self.mesh.close()
