"""The geometric episode's modes, each a str enum (its values are the names the command line
and the reports use): `GeoPlanner`, which planner plans; `Observation`, which sensor reads the
object poses. No import beyond `enum`, so the parser can name them."""

from __future__ import annotations

import enum


class GeoPlanner(enum.StrEnum):
    """The geometric episode's planners by name (`tamp.geo.episode.planner_by_name`), in the
    order ``tamp run --geo-planner`` lists them: ours, the baseline, the complete search alone,
    task-only planning, ours with rejection-sampled region cells (an ablation)."""

    MOTION_AWARE = "motion-aware"
    SEARCH_THEN_CHECK = "search-then-check"
    SEARCH = "search"
    SOFT = "soft"
    MOTION_AWARE_SAMPLED = "motion-aware-sampled"


class Observation(enum.StrEnum):
    """An episode's pose sensor: STATE, the motion-capture oracle (`tamp.loop.sensors`); CAMERA,
    poses estimated from RGB-D images (the loop's `CameraPoses`, the geometric episode's
    `tamp.camera.scene_poses.ScenePoses`)."""

    STATE = "state"
    CAMERA = "camera"
