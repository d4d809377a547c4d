"""tamp: the loop observe -> perceive -> plan -> execute -> check -> replan, and the CLI.

The one package that sees every other one. ``tamp.api`` is the entry layer for Python users
(plan, validate, run an episode, execute a given plan, scenes, images, benchmarks, move costs).
Its rooms:

- ``tamp.loop``: closed-loop episodes in a simulator (observe, plan a window, execute a move,
  check, recover or replan), fault injection;
- ``tamp.sim``: the `Simulator` interface, the PyBullet and MuJoCo backends, the factory;
- ``tamp.camera``: rendering symbolic states, rendered perception datasets, planning beliefs
  from camera images;
- ``tamp.bench``: every benchmark (PlanBench, random, motion, perception), one results writer,
  one table printer;
- ``tamp.cli``: the ``tamp`` command (parsing and printing only);
- ``tamp.world``: scene files (table, regions, obstacles, movable objects) and the symbolic
  state and goals read from their geometry;
- ``tamp.scene``: the table, its slots and block poses <-> symbolic states;
  ``tamp.obstacles``: the named scenes and the clearance they leave;
  ``tamp.arm``: the arm's cost of each move, for motion-aware planning, and what it failed;
  ``tamp.sweep``: independent items (episodes) in local processes or on a Ray cluster;
  ``tamp.video``: episode videos.
"""
