"""TAMP over a scene's geometry: objects of any size, regions, grasps and placements as choices.

Where `tamp.loop` runs Blocksworld moves of same-size cubes onto a slot grid, this room plans
and runs pick-and-place problems read from a scene file (`tamp.world`): the symbolic state is
read from the geometry, a move names the object, the grasp it is held by and the placement it
goes to, and a move's feasibility is decided by the arm (IK and collision checks), not assumed.

- `tamp.geo.types`: the values every part shares (`Place`, `GeoMove`, `GeoPlan`, `GeoStatus`)
  and the world after a move (`moved`).
- `tamp.geo.places`: `candidate_places`, the discretised placements of an object on an
  object, in a region or on the table, with names stable across world states.
- `tamp.geo.check`: `check_move` (and its cheap half `quick_check`), a move decided by the
  arm's IK and collision model, grasp by grasp; `Tools` builds those models once.
- `tamp.geo.search`: `plan_search`, best-first search over world states with feasibility
  checked lazily and a failure memory keyed by where each failure lies (`SearchConfig`).
- `tamp.geo.baseline`: `plan_search_then_check`, symbolic planning, then binding to
  geometry, failed moves forbidden, replanning.
- `tamp.geo.execute`: `run_move`, one checked move run in a simulator with its failures read
  from the gripper.
- `tamp.geo.config`: `GeoEpisodeConfig`, the settings of one episode.
- `tamp.geo.episode`: `run_geo_episode`, observe, plan, check, run and replan with one of the
  planners (`GeoPlanner`), an `EpisodeReport` (`tamp.episode_report`, the loop's too) scored on
  ground truth.
- `tamp.geo.scene_file`: `scene_episode`, which episode runs a scene file (``tamp run
  --scene``): the Blocksworld loop's `SceneTask` or a `GeoRun` for `run_geo_episode`.
"""
