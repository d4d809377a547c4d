"""The TAMP benchmark (``tamp bench tamp``): the canonical problems where geometry decides the plan.

- ``run``: seeded variants of each canonical problem (`tamp.world.canonical`) played as
  geometric TAMP episodes (`tamp.geo.episode.run_geo_episode`) by each planner in each
  simulator; one row per episode, summaries per (problem, planner, simulator).

The table printer is `tamp.bench.tables.tamp_table`; the results writer `tamp.bench.results`.
"""
