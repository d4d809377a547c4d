"""The named workcells as scene files (`tamp.world.convert.workcells`): each shipped file is
what ``scripts/workcell_scenes.py`` writes from `tamp.obstacles`, so the two cannot drift."""

from __future__ import annotations

import pytest

from tamp.obstacles import SCENES, with_scene
from tamp.scene import SceneConfig
from tamp.world import load_named, scene_config
from tamp.world.convert.workcells import workcell_scene, write_workcells
from tamp.world.load import SCENES_DIR
from task.errors import TampError


def test_the_shipped_files_are_what_the_script_writes_from_tamp_obstacles(tmp_path):
    written = write_workcells(tmp_path)
    assert sorted(p.stem for p in written) == sorted(SCENES)
    for path in written:
        assert path.read_text() == (SCENES_DIR / path.name).read_text(), path.name


@pytest.mark.parametrize("name", sorted(SCENES))
def test_each_workcell_file_loads_with_the_python_definitions_obstacles_and_slots(name):
    loaded = load_named(name)
    assert loaded == workcell_scene(name)
    assert loaded.obstacles == SCENES[name]
    assert not loaded.objects and not loaded.regions
    assert scene_config(loaded) == with_scene(SceneConfig(), name)


def test_an_unknown_workcell_lists_the_workcells():
    with pytest.raises(TampError, match=r"unknown scene 'attic'.*tabletop"):
        workcell_scene("attic")
