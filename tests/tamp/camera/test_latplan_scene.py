"""LatPlan's cylinder scene in both simulators, its camera, and its randomised dataset."""

from __future__ import annotations

import json

import numpy as np
import pytest

from perception import data as pdata
from tamp.camera import latplan
from tamp.camera.render import StateRenderer
from tamp.scene import SceneConfig, SceneError, layout, towers
from task.problem import TABLE

pytestmark = pytest.mark.sim

NAMES = ("a", "b", "c", "d")
STATE = ("b", TABLE, TABLE, TABLE)  # a on b; b, c, d on the table: 3 towers


def test_camera_is_the_generators_at_150x100():
    cam = latplan.latplan_camera()
    k = latplan.unit()
    assert (cam.width, cam.height) == (150, 100)
    assert cam.eye == pytest.approx((latplan.ROW_X, -16 * k, 6 * k))
    assert cam.target == pytest.approx((latplan.ROW_X, 0.0, 3 * k))
    assert cam.fovy == pytest.approx(33.898, abs=1e-3)  # 35 mm lens, 32 mm sensor across 150 px


def test_layout_puts_towers_on_the_five_slots_of_one_row():
    scene = latplan.latplan_scene()
    assert len(scene.slots) == 5 and {y for _, y in scene.slots} == {0.0}
    gaps = np.diff(scene.slot_xs)
    assert gaps == pytest.approx([1.75 * latplan.unit()] * 4)
    poses = layout(NAMES, STATE, scene, seed=3, slots=[4, 0, 2])
    xs = {x: p.xyz[0] for x, p in poses.items()}
    assert xs["b"] == pytest.approx(scene.slot_xs[4]) and xs["a"] == pytest.approx(xs["b"])
    assert xs["c"] == pytest.approx(scene.slot_xs[0]) and xs["d"] == pytest.approx(scene.slot_xs[2])
    zs = sorted(p.xyz[2] for p in poses.values())
    assert zs == pytest.approx([0.025, 0.025, 0.025, 0.075])  # LatPlan's z = 0.7, 0.7, 0.7, 2.1
    with pytest.raises(SceneError, match="own slot"):
        layout(NAMES, STATE, scene, slots=[1, 1, 2])


def test_default_scene_is_still_cubes():
    assert SceneConfig().shape == "cube"
    with pytest.raises(SceneError, match="unknown block shape"):
        SceneConfig(shape="sphere")


def _colour_found(image: np.ndarray, rgb) -> bool:
    """A few pixels near the nominal colour (dark for black) beside the grey floor."""
    img = image.astype(int)
    spread = img.max(-1) - img.min(-1)
    if max(rgb) == 0:  # black: dark and unsaturated, darker than any floor or shadow here
        return int(((img.max(-1) < 40) & (spread < 25)).sum()) >= 10
    channel = int(np.argmax(rgb))
    others = [c for c in range(3) if c != channel]
    strong = (img[..., channel] > 80) & (img[..., channel] > img[..., others].max(-1) + 50)
    return int(strong.sum()) >= 10


@pytest.mark.parametrize("sim", ["pybullet", "mujoco"])
def test_cylinders_of_all_four_colours_render_at_150x100(sim):
    scene = latplan.latplan_scene()
    with StateRenderer(sim, scene, latplan.latplan_camera()) as renderer:
        image = renderer.render(NAMES, STATE, seed=0, colours=[0, 1, 2, 3], slots=[0, 2, 4])
        alone = renderer.render(("a",), (TABLE,), seed=0, colours=[1], slots=[2])
    assert image.shape == (100, 150, 3) and image.dtype == np.uint8
    for name, rgb in latplan.COLOURS:
        assert _colour_found(image, rgb), f"{name} not visible in the {sim} render"
        if name in ("red", "green"):
            assert not _colour_found(alone, rgb), f"{name} seen beside a lone blue block"


def _write_scene(path, slots):
    """A scene_tr JSON with the given {colour: (slot, level)}."""
    rgb = dict(latplan.COLOURS)
    objects = [
        {"color": [*rgb[c], 1.0], "location": [latplan.SLOTS_CLEVR[s], 0, 0.7 + 1.4 * lvl]}
        for c, (s, lvl) in slots.items()
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"objects": objects}))


def test_scene_json_layouts_are_read_by_slot_and_level(tmp_path):
    assert latplan.evaluation_layouts(tmp_path / "absent") is None
    scene = {"black": (1, 1), "red": (1, 0), "green": (4, 0), "blue": (1, 2)}
    _write_scene(tmp_path / "001" / "scene_tr" / "init.json", scene)
    layouts = latplan.evaluation_layouts(tmp_path)
    assert layouts == {((), ("red", "black", "blue"), (), (), ("green",))}


def test_tiny_dataset_has_both_sizes_labels_and_metadata():
    out = latplan.generate(4, seed=1)
    big, small = out[(150, 100)], out[(45, 30)]
    assert big.images.shape == (4, 100, 150, 3) and small.images.shape == (4, 30, 45, 3)
    assert big.colours.shape == big.supports.shape == (4, 4)
    assert (np.sort(big.colours, axis=1) == np.arange(4)).all()  # all four colours, every image
    assert np.array_equal(big.supports, small.supports)
    for supports, slots in zip(big.supports, big.meta["slots"], strict=True):
        for x, (sup, slot) in enumerate(zip(supports, slots, strict=True)):
            assert 0 <= slot < 5
            assert sup == pdata.TABLE or slots[sup] == slot  # in its support's column
            assert sup != x
    meta = big.meta
    assert meta["camera"]["fitted_from_evaluation_scenes"] is False
    assert meta["evaluation_layouts_excluded"] is False and meta["excluded_from"] is None
    assert meta["size"] == [150, 100] and small.meta["size"] == [45, 30]
    json.dumps(meta)  # stored as JSON by perception.data.save


def test_excluded_layouts_are_never_drawn():
    kept = latplan.generate(1, seed=5, sims=("pybullet",))[(150, 100)]
    names = ["a", "b", "c", "d"]
    state = [TABLE if s == pdata.TABLE else names[s] for s in kept.supports[0]]
    tower_slots = {}
    for x, s, slot in zip(names, state, kept.meta["slots"][0], strict=True):
        if s == TABLE:
            tower_slots[x] = slot
    bases = [t[0] for t in towers(names, state)]
    drawn = latplan.layout_of(names, kept.colours[0], state, [tower_slots[b] for b in bases])
    again = latplan.generate(1, seed=5, sims=("pybullet",), exclude=[drawn], exclude_source="test")
    meta = again[(150, 100)].meta
    assert meta["evaluation_layouts_excluded"] is True and meta["excluded_from"] == "test"
    assert meta["redrawn_as_excluded"] >= 1
    assert not np.array_equal(again[(150, 100)].images, kept.images)


def test_cli_writes_both_sizes(tmp_path, capsys):
    from tamp.cli import main

    out = tmp_path / "lp.npz"
    argv = ["perception", "dataset", "--image-scene", "latplan", "--n", "2", "--sim", "pybullet"]
    assert main([*argv, "--out", str(out), "--no-progress", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["images"] == 2 and len(report["out"]) == 2
    assert pdata.load(out).images.shape[1:3] == (100, 150)
    assert pdata.load(tmp_path / "lp_45x30.npz").images.shape[1:3] == (30, 45)
