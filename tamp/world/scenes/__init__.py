"""The scene files shipped with soft-tamp (schema in `tamp.world.schema`): today's named scenes
``tabletop``, ``shelf``, ``clutter`` and ``cramped`` (kept equal to `tamp.obstacles` by
tests/tamp/world), and ``tray``, an example with a walled region and objects of every kind.
Load one with `tamp.world.load_named`."""
