"""The scene files shipped with soft-tamp (schema in `tamp.world.schema`): today's named scenes
``tabletop``, ``shelf``, ``clutter`` and ``cramped`` (written from `tamp.obstacles`, their
source, by ``scripts/workcell_scenes.py``; tests/tamp/world/test_workcells.py keeps them
equal), and ``tray``, an example with a walled region and objects of every kind. Load one with
`tamp.world.load_named`."""
