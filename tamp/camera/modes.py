"""How the planner gets its states from the camera's images, each setting a str enum (its values
are the names the command line and the reports use): `Perception`, `Adapt`, `Crisp`. No import
beyond `enum`, so the parser can name them."""

from __future__ import annotations

import enum


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
