"""TAMP over a scene's geometry: objects of any size, regions, grasps and placements as choices.

Where `tamp.loop` runs Blocksworld moves of same-size cubes onto a slot grid, this room plans
and runs pick-and-place problems read from a scene file (`tamp.world`): the symbolic state is
read from the geometry, a move names the object, the grasp it is held by and the placement it
goes to, and a move's feasibility is decided by the arm (IK and collision checks), not assumed.

- `tamp.geo.types`: the values every part shares (`Place`, `GeoMove`, `GeoPlan`, `GeoStatus`)
  and the world after a move (`moved`).
"""
