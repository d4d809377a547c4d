"""The batched, conservative collision check of the Panda against boxes over a sphere model.

A room of its own: `fk` (the sphere model's batched forward kinematics), `bounds` (its bounding
volumes and distance tests), `model` (`SphereModel`: the fixed geometry of the checks' phases,
built once), `collision` (`SphereCollision`: the scene, the held box and the batched check, with
`robots.collision.PandaCollision`'s interface plus ``valid_batch``) and `screened` (`Screened`:
a mesh model with the spheres beside it, for the motion planner's batches).

Its API, re-exported here: `SphereCollision` and `Screened`.
"""

from motion.sphere_check.collision import SphereCollision
from motion.sphere_check.screened import Screened

__all__ = ["Screened", "SphereCollision"]
