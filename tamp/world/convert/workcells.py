"""The named workcells as scene files: ``tamp/world/scenes/<name>.json`` written from
`tamp.obstacles`.

`tamp.obstacles.SCENES` (with its slot grids, `tamp.obstacles.GRIDS`) is the source of the four
workcells ``tabletop``, ``shelf``, ``clutter`` and ``cramped``; `workcell_scene` is one as a
`tamp.world.Scene` (the shipped table, the workcell's slot grid and obstacles, no objects) and
`write_workcells` writes all four as schema-1 files. ``scripts/workcell_scenes.py`` runs it; the
files are committed, and tests/tamp/world/test_workcells.py fails when a file and its Python
definition drift apart.
"""

from __future__ import annotations

from pathlib import Path

from tamp.obstacles import SCENES, with_scene
from tamp.scene import SceneConfig
from tamp.world.generators import TABLE_TOP
from tamp.world.load import SCENES_DIR, save_scene
from tamp.world.schema import Scene, Slots


def workcell_scene(name: str) -> Scene:
    """The named workcell (`tamp.obstacles.SCENES`) as a scene without objects; TampError
    listing the workcells for an unknown name."""
    config = with_scene(SceneConfig(), name)
    slots = Slots(config.slot_xs, config.slot_ys)
    return Scene(name, TABLE_TOP, obstacles=config.obstacles, slots=slots)


def write_workcells(directory: str | Path = SCENES_DIR) -> tuple[Path, ...]:
    """Every workcell as ``<directory>/<name>.json``; the paths written."""
    directory = Path(directory)
    return tuple(save_scene(workcell_scene(n), directory / f"{n}.json") for n in sorted(SCENES))
