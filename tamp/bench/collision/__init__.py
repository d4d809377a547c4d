"""The collision checker benchmark (``tamp bench checker``): the sphere model against the meshes.

- ``scenes``: the obstacle scenes it runs on (a named scene's boxes and seeded towers of blocks
  on its slots) and the seeded configuration samples (the joint box, near obstacles, moves the
  straight path cannot make).
- ``run``: configurations per second of `motion.sphere_check.SphereCollision.valid_batch` on one
  core, its verdicts against the mesh model's (`robots.collision.PandaCollision`, PyBullet's
  closest points) near obstacles, and rerouted moves planned by `motion.rrt.plan_path` with the
  guard's settings, beside OMPL's RRT-Connect on the mesh model alone.
- ``threads``: one core for the throughput (every thread of the process on one CPU, OpenBLAS's
  and torch's pools at one thread) and a count of the threads that worked.

The table printer is `tamp.bench.tables.checker_table`; the results writer `tamp.bench.results`.
"""
