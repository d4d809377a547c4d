"""The modes of an episode and of its planning, each a str enum whose values are the names
the command line, the configs and the reports use: `GeoPlanner` (which planner plans a
geometric episode), `Observation` (which sensor reads the object poses), `Perception`,
`Adapt` and `Crisp` (how the planner gets its states from the camera's images) and
`ImageScene` (whose objects an image shows). One home for them, importing nothing beyond
`enum`, so the parser names them without loading the stack.
"""

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


class Perception(enum.StrEnum):
    """Where the planner's states come from: STATE, the true states (no image read); FROZEN,
    the perception model's reading of the images; OPTIMISED, that reading with the model's
    weights adapted by the planning loss."""

    STATE = "state"
    FROZEN = "frozen"
    OPTIMISED = "optimised"


class Adapt(enum.StrEnum):
    """Which weights `Perception.OPTIMISED` updates: the bilinear HEAD, or ALL of them."""

    HEAD = "head"
    ALL = "all"


class Crisp(enum.StrEnum):
    """What decoded moves are checked against: the TRUE state, or the PERCEIVED one (the
    image's reading, what a robot has)."""

    TRUE = "true"
    PERCEIVED = "perceived"


class ImageScene(enum.StrEnum):
    """Whose objects an image shows, and so which colours the reading names: CUBES, the
    project's rendered cubes; LATPLAN, LatPlan's blocks-world renders (cubes and cylinders)."""

    CUBES = "cubes"
    LATPLAN = "latplan"
