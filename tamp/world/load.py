"""Reading and writing scene files: the schema's checks and the geometry's, one line per fault.

`load_scene` takes a path or an already-parsed dict and returns a `tamp.world.schema.Scene`, or
raises `SceneFileError` with one line ``<source>: <field>: <problem>``, the field written as a
path such as ``objects[2] (c).pose.xyz``. It refuses: a missing or unknown field (listing the
valid ones), a value of the wrong type or range, an unknown schema version, a duplicate name, a
region outside the table or with none of its area within the arm's reach, two things
overlapping, an object floating, sunk into the table, off the table or out of the arm's reach.
`scene_dict` and `save_scene` write a scene back
(``load_scene(scene_dict(s)) == s``); `load_named` reads the scenes shipped with the package.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from motion.grasps import KINDS
from tamp.obstacles import Obstacle
from tamp.scene import PALETTE, Body, Pose, SceneConfig
from tamp.sim.base import Camera
from tamp.world.geometry import (
    TIGHT,
    Solid,
    Tolerances,
    fixed_solids,
    footprint_gap,
    of_movable,
    penetration,
    support,
)
from tamp.world.schema import (
    SCHEMA,
    Movable,
    Region,
    Scene,
    SceneFileError,
    Slots,
    Table,
)
from task.errors import one_of
from task.problem import TABLE

# The Panda's reach for a top-down grasp, measured with `motion.ik.IKSolver` (TCP pointing
# down, from the home pose): at z = 0.025 m IK converges out to 0.80 m from the base's z axis
# and fails from 0.825 m; at z = 0.3 m out to 0.775 m; nearer than 0.25 m it fails at table
# height. An object's centre must lie between these horizontal distances from the base axis.
MIN_REACH = 0.25  # m
MAX_REACH = 0.78  # m

MARK_THICKNESS = 0.001  # m, the drawn patch of a region without walls (`scene_config`)

SCENES_DIR = Path(__file__).resolve().parent / "scenes"
NAME = re.compile(r"^[a-z][a-z0-9_-]*$")

TOP = {"schema", "name", "table"}
TOP_OPTIONAL = {"slots", "regions", "obstacles", "objects", "camera", "parking"}
REGION = {"name", "min", "max"}
REGION_OPTIONAL = {"on", "floor", "wall_height", "wall_thickness", "colour"}
OBSTACLE = {"name", "centre", "half"}
OBSTACLE_OPTIONAL = {"yaw", "colour"}
OBJECT = {"name", "kind", "size", "colour", "pose"}
CAMERA = {"eye", "target"}
CAMERA_OPTIONAL = {"up", "fovy", "width", "height"}
SIZES = {"cube": 1, "cuboid": 3, "cylinder": 2}  # numbers in "size" per kind
GREY = (0.62, 0.62, 0.6)  # `tamp.obstacles.Obstacle`'s default colour
BROWN = (0.5, 0.3, 0.1)  # a region's default colour


def load_scene(source: str | Path | Mapping, tolerances: Tolerances = TIGHT) -> Scene:
    """The scene in the JSON file at ``source`` (or the dict ``source``), checked."""
    if isinstance(source, Mapping):
        data, label = source, "scene"
    else:
        path = Path(source)
        label = str(path)
        try:
            text = path.read_text()
        except OSError as exc:
            raise SceneFileError(f"{label}: cannot read the scene file ({exc.strerror})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SceneFileError(
                f"{label}: not JSON: {exc.msg} at line {exc.lineno} column {exc.colno}"
            ) from None
    try:
        scene = _parse(data)
        _check(scene, tolerances)
    except _Fault as fault:
        raise SceneFileError(f"{label}: {fault.args[0]}") from None
    return scene


def named_scenes() -> tuple[str, ...]:
    """The names of the scene files shipped in ``tamp/world/scenes``."""
    return tuple(sorted(p.stem for p in SCENES_DIR.glob("*.json")))


def load_named(name: str, tolerances: Tolerances = TIGHT) -> Scene:
    """A shipped scene by name (e.g. ``tabletop``, ``shelf``, ``clutter``, ``cramped``)."""
    if name not in named_scenes():
        raise SceneFileError(f"unknown scene {one_of(name, named_scenes())}")
    return load_scene(SCENES_DIR / f"{name}.json", tolerances)


def scene_config(scene: Scene, base: SceneConfig = SceneConfig()) -> SceneConfig:
    """The simulators' scene model (`tamp.scene.SceneConfig`) of this scene: ``base`` with the
    scene's name, its obstacles followed by its regions' walls and base slabs as fixed boxes,
    its slot grid (``base``'s grid when the scene has none) and, when it has movable objects,
    each object's solid (``bodies``, `tamp.scene.Body` from its kind and half extents) and
    colour (``palette``: object i, in the scene's order, has colour i). Each region without
    walls is also a visual-only mark (``marks``, `_mark`) so that camera images show it."""
    grid = {} if scene.slots is None else {"slot_xs": scene.slots.xs, "slot_ys": scene.slots.ys}
    boxes = [b for r in scene.regions for b in (*r.walls(), r.slab()) if b is not None]
    marks = tuple(_mark(r) for r in scene.regions if r.wall_height <= 0)
    config = replace(
        base, name=scene.name, obstacles=(*scene.obstacles, *boxes), marks=marks, **grid
    )
    if not scene.objects:  # a workcell: the loop's blocks keep base's bodies and colours
        return config
    bodies = tuple((o.name, Body(o.kind, o.half)) for o in scene.objects)
    palette = tuple((o.name, o.rgb) for o in scene.objects)
    return replace(config, bodies=bodies, palette=palette)


def _mark(r: Region) -> Obstacle:
    """The flat patch drawn over a region without walls, in its colour: its rectangle,
    `MARK_THICKNESS` thick, from 1 mm above its surface (PyBullet's table is drawn up to
    z = 0.001). Visual only: the simulators give it no collision."""
    centre = ((r.lo[0] + r.hi[0]) / 2, (r.lo[1] + r.hi[1]) / 2, r.surface + 0.001)
    half = ((r.hi[0] - r.lo[0]) / 2, (r.hi[1] - r.lo[1]) / 2, MARK_THICKNESS / 2)
    return Obstacle(f"{r.name}:mark", (*centre[:2], centre[2] + half[2]), half, rgb=r.rgb)


class _Fault(Exception):
    """One fault, ``<field>: <problem>``; `load_scene` prefixes the source."""


# ---- the schema -------------------------------------------------------------------------------


def _fields(value, where: str, required: set[str], optional: set[str] = frozenset()) -> dict:
    if not isinstance(value, Mapping):
        raise _Fault(f"{where}: expected an object {{...}}, got {_type(value)}")
    valid = sorted(required | optional)
    for key in value:
        if key not in required | optional:
            raise _Fault(f"{_join(where, key)}: unknown field (valid: {', '.join(valid)})")
    for key in sorted(required):
        if key not in value:
            raise _Fault(f"{_join(where, key)}: missing (required: {', '.join(sorted(required))})")
    return dict(value)


def _join(where: str, key: str) -> str:
    return key if not where else f"{where}.{key}"


def _type(value) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), type(value).__name__
    )


def _number(value, where: str, low: float | None = None, strict: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _Fault(f"{where}: expected a number, got {_type(value)} {value!r}")
    if low is not None and (value <= low if strict else value < low):
        sign = ">" if strict else ">="
        raise _Fault(f"{where}: must be {sign} {low}, got {value}")
    return float(value)


def _vector(value, where: str, n: int, low: float | None = None, strict: bool = False):
    if not isinstance(value, list) or len(value) != n:
        raise _Fault(f"{where}: expected a list of {n} numbers, got {_type(value)} {value!r}")
    return tuple(_number(v, f"{where}[{i}]", low, strict) for i, v in enumerate(value))


def _name(value, where: str) -> str:
    if not isinstance(value, str) or not NAME.match(value):
        raise _Fault(
            f"{where}: expected a PDDL name (lowercase letter, then letters, digits, - or _), "
            f"got {value!r}"
        )
    if value == TABLE:
        raise _Fault(f"{where}: {TABLE!r} is reserved for the table")
    return value


def _colour(value, where: str) -> tuple[float, float, float]:
    names = dict(PALETTE)
    if isinstance(value, str):
        if value not in names:
            raise _Fault(f"{where}: unknown colour {one_of(value, names)}")
        return names[value]
    rgb = _vector(value, where, 3, 0.0)
    if max(rgb) > 1:
        raise _Fault(f"{where}: RGB values lie in [0, 1], got {list(rgb)}")
    return rgb


def _list(data: dict, key: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise _Fault(f"{key}: expected a list, got {_type(value)}")
    return value


def _parse(data) -> Scene:
    data = _fields(data, "", TOP, TOP_OPTIONAL)
    version = data["schema"]
    if version != SCHEMA or isinstance(version, bool):
        raise _Fault(f"schema: unknown version {version!r} (this code reads version {SCHEMA})")
    if not isinstance(data["name"], str) or not data["name"]:
        raise _Fault(f"name: expected a non-empty string, got {data['name']!r}")
    t = _fields(data["table"], "table", {"min", "max"})
    table = Table(_vector(t["min"], "table.min", 2), _vector(t["max"], "table.max", 2))
    if not all(table.lo[i] < table.hi[i] for i in range(2)):
        raise _Fault(f"table: min {list(table.lo)} must lie below max {list(table.hi)} in x and y")
    slots = None
    if "slots" in data:
        s = _fields(data["slots"], "slots", {"xs", "ys"})
        slots = Slots(*(_coordinates(s[k], f"slots.{k}") for k in ("xs", "ys")))
    obstacles = tuple(
        _obstacle(o, f"obstacles[{i}]") for i, o in enumerate(_list(data, "obstacles"))
    )
    regions = tuple(
        _region(r, f"regions[{i}]", obstacles) for i, r in enumerate(_list(data, "regions"))
    )
    objects = tuple(_object(o, f"objects[{i}]") for i, o in enumerate(_list(data, "objects")))
    camera = _camera(data["camera"]) if "camera" in data else None
    parking = data.get("parking", True)
    if not isinstance(parking, bool):
        raise _Fault(f"parking: expected true or false, got {parking!r}")
    return Scene(
        name=data["name"],
        table=table,
        regions=regions,
        obstacles=obstacles,
        objects=objects,
        slots=slots,
        camera=camera,
        parking=parking,
    )


def _coordinates(value, where: str) -> tuple[float, ...]:
    if not isinstance(value, list) or not value:
        raise _Fault(f"{where}: expected a non-empty list of numbers, got {value!r}")
    return tuple(_number(v, f"{where}[{i}]") for i, v in enumerate(value))


def _label(value, where: str) -> str:
    """``where`` with the item's name, when it has a usable one: ``objects[2] (c)``."""
    name = value.get("name") if isinstance(value, Mapping) else None
    return f"{where} ({name})" if isinstance(name, str) and name else where


def _obstacle(value, where: str) -> Obstacle:
    where = _label(value, where)
    o = _fields(value, where, OBSTACLE, OBSTACLE_OPTIONAL)
    return Obstacle(
        _name(o["name"], f"{where}.name"),
        _vector(o["centre"], f"{where}.centre", 3),
        _vector(o["half"], f"{where}.half", 3, 0.0, strict=True),
        _number(o.get("yaw", 0.0), f"{where}.yaw"),
        _colour(o.get("colour", list(GREY)), f"{where}.colour"),
    )


def _region(value, where: str, obstacles: tuple[Obstacle, ...]) -> Region:
    where = _label(value, where)
    r = _fields(value, where, REGION, REGION_OPTIONAL)
    lo, hi = _vector(r["min"], f"{where}.min", 2), _vector(r["max"], f"{where}.max", 2)
    if not all(lo[i] < hi[i] for i in range(2)):
        raise _Fault(f"{where}.max: {list(hi)} must lie above min {list(lo)} in x and y")
    base = 0.0
    on = r.get("on")
    if on is not None:
        names = [o.name for o in obstacles]
        if on not in names:
            raise _Fault(f"{where}.on: unknown obstacle {one_of(on, names)}")
        board = obstacles[names.index(on)]
        corners = [(x, y) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
        if not all(board.covers(c, 1e-9) for c in corners):
            raise _Fault(f"{where}: the rectangle reaches beyond the top of obstacle {on!r}")
        base = board.centre[2] + board.half[2]
    floor = _number(r.get("floor", 0.0), f"{where}.floor", 0.0)
    height = _number(r.get("wall_height", 0.0), f"{where}.wall_height", 0.0)
    thick = _number(r.get("wall_thickness", 0.01), f"{where}.wall_thickness", 0.0, strict=True)
    if height > 0 and 2 * thick >= min(hi[0] - lo[0], hi[1] - lo[1]):
        raise _Fault(f"{where}.wall_thickness: {thick} m walls leave no room inside the region")
    rgb = _colour(r.get("colour", list(BROWN)), f"{where}.colour")
    name = _name(r["name"], f"{where}.name")
    return Region(
        name=name,
        lo=lo,
        hi=hi,
        surface=base + floor,
        floor=floor,
        on=on,
        wall_height=height,
        wall_thickness=thick,
        rgb=rgb,
    )


def _object(value, where: str) -> Movable:
    where = _label(value, where)
    o = _fields(value, where, OBJECT)
    kind = o["kind"]
    if kind not in KINDS:
        raise _Fault(f"{where}.kind: unknown kind {one_of(kind, KINDS)}")
    n = SIZES[kind]
    size = o["size"]
    if n == 1:
        size = (_number(size, f"{where}.size", 0.0, strict=True),)
    else:
        size = _vector(size, f"{where}.size", n, 0.0, strict=True)
    p = _fields(o["pose"], f"{where}.pose", {"xyz"}, {"yaw"})
    pose = Pose(
        _vector(p["xyz"], f"{where}.pose.xyz", 3), _number(p.get("yaw", 0.0), f"{where}.pose.yaw")
    )
    rgb = _colour(o["colour"], f"{where}.colour")
    return Movable(_name(o["name"], f"{where}.name"), kind, size, rgb, pose)


def _camera(value) -> Camera:
    c = _fields(value, "camera", CAMERA, CAMERA_OPTIONAL)
    default = Camera()
    eye, target = _vector(c["eye"], "camera.eye", 3), _vector(c["target"], "camera.target", 3)
    if eye == target:
        raise _Fault("camera.target: the camera looks from its eye at its eye")
    size = {}
    for key in ("width", "height"):
        v = c.get(key, getattr(default, key))
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise _Fault(f"camera.{key}: expected a positive whole number of pixels, got {v!r}")
        size[key] = v
    fovy = _number(c.get("fovy", default.fovy), "camera.fovy", 0.0, strict=True)
    if fovy >= 180:
        raise _Fault(f"camera.fovy: must be below 180 degrees, got {fovy}")
    up = _vector(c.get("up", list(default.up)), "camera.up", 3)
    return Camera(eye, target, up, fovy, **size)


# ---- geometry ---------------------------------------------------------------------------------


def _check(scene: Scene, tol: Tolerances) -> None:
    _unique(scene)
    for i, r in enumerate(scene.regions):
        for key, corner in (("min", r.lo), ("max", r.hi)):
            if not scene.table.holds(corner, 1e-9):
                raise _Fault(
                    f"regions[{i}] ({r.name}).{key}: corner {list(corner)} lies outside the "
                    f"table (x {scene.table.lo[0]}..{scene.table.hi[0]}, "
                    f"y {scene.table.lo[1]}..{scene.table.hi[1]} m)"
                )
        _region_reach(r, f"regions[{i}] ({r.name})")
    if scene.slots is not None:
        for x in scene.slots.xs:
            for y in scene.slots.ys:
                if not scene.table.holds((x, y)):
                    raise _Fault(f"slots: slot ({x}, {y}) lies outside the table")
    fixed = fixed_solids(scene)
    solids = [of_movable(o) for o in scene.objects]
    for i, o in enumerate(scene.objects):
        where = f"objects[{i}] ({o.name}).pose.xyz"
        if not scene.table.holds(o.pose.xyz):
            raise _Fault(f"{where}: {_xy(o)} lies off the table")
        if o.bottom < -tol.z:
            raise _Fault(f"{where}: sunk {_mm(-o.bottom)} into the table (bottom at z = 0)")
        for j, other in enumerate([*solids[i + 1 :], *fixed], start=i + 1):
            depth = penetration(solids[i], other)
            if depth <= tol.overlap:
                continue
            if j < len(solids) and _sunk(other, solids[i]):  # the other sits too low
                here = f"objects[{j}] ({other.name}).pose.xyz"
                raise _Fault(f"{here}: {other.name} sunk into {o.name} by {_mm(depth)}")
            what = "sunk into" if _sunk(solids[i], other) else "overlaps"
            raise _Fault(f"{where}: {o.name} {what} {other.name} by {_mm(depth)}")
        rest = support(scene, o, tol)
        if not rest.faces:
            raise _Fault(f"{where}: floats, {_below(scene, o, tol)}")
        if not rest.under_centre and len(rest.faces) < 2:
            raise _Fault(f"{where}: tips off {rest.faces[0]}: its centre is not over it")
        if not MIN_REACH <= o.reach <= MAX_REACH:
            raise _Fault(
                f"{where}: out of the arm's reach, {o.reach:.3f} m from the robot base's axis "
                f"(the Panda reaches {MIN_REACH} to {MAX_REACH} m)"
            )


def _sunk(upper: Solid, lower: Solid) -> bool:
    """True when ``upper`` interpenetrates ``lower`` from above: its centre above ``lower``'s
    top and their overlap in height no deeper than on the table. Beside a low wall or object,
    overlapping it from the side, an object is not sunk into it but overlaps it."""
    dz = min(upper.top, lower.top) - max(upper.bottom, lower.bottom)
    return upper.centre[2] > lower.top and dz <= -footprint_gap(upper, lower)


def _region_reach(r: Region, where: str) -> None:
    """Refuse a region none of whose rectangle lies between `MIN_REACH` and `MAX_REACH` from
    the robot base's axis (a region partly within reach is fine)."""
    near = math.hypot(*(min(max(0.0, r.lo[k]), r.hi[k]) for k in range(2)))
    far = max(math.hypot(x, y) for x in (r.lo[0], r.hi[0]) for y in (r.lo[1], r.hi[1]))
    if near <= MAX_REACH and far >= MIN_REACH:
        return
    what = f"its nearest point {near:.3f} m" if near > MAX_REACH else f"its farthest {far:.3f} m"
    raise _Fault(
        f"{where}: out of the arm's reach, {what} from the robot base's axis "
        f"(the Panda reaches {MIN_REACH} to {MAX_REACH} m)"
    )


def _unique(scene: Scene) -> None:
    seen: dict[str, str] = {}
    for group, items in (
        ("obstacles", scene.obstacles),
        ("regions", scene.regions),
        ("objects", scene.objects),
    ):
        for i, item in enumerate(items):
            if item.name in seen:
                raise _Fault(
                    f"{group}[{i}].name: {item.name!r} is already the name of {seen[item.name]}"
                )
            seen[item.name] = f"{group}[{i}]"


def _xy(o: Movable) -> str:
    return f"({o.pose.xyz[0]:.3f}, {o.pose.xyz[1]:.3f})"


def _mm(metres: float) -> str:
    return f"{metres * 1000:.0f} mm"


def _below(scene: Scene, o: Movable, tol: Tolerances) -> str:
    """Where ``o``'s bottom is and the nearest face under it, for the floating message."""
    me = of_movable(o)
    tops = [(0.0, "the table")]
    for s in [*(of_movable(x) for x in scene.objects if x.name != o.name), *fixed_solids(scene)]:
        if s.top <= o.bottom and (s.covers(o.pose.xyz) or me.covers(s.centre)):
            tops.append((s.top, s.name))
    tops += [(r.surface, f"region {r.name}") for r in scene.regions if r.surface <= o.bottom]
    z, name = max(tops)
    return f"its bottom {_mm(o.bottom - z)} above {name} (rests on nothing within {_mm(tol.z)})"


# ---- writing ----------------------------------------------------------------------------------


def scene_dict(scene: Scene) -> dict:
    """The scene as schema-1 JSON data (every field written out)."""
    out: dict = {
        "schema": SCHEMA,
        "name": scene.name,
        "table": {"min": list(scene.table.lo), "max": list(scene.table.hi)},
    }
    if scene.slots is not None:
        out["slots"] = {"xs": list(scene.slots.xs), "ys": list(scene.slots.ys)}
    out["regions"] = [_region_dict(r) for r in scene.regions]
    out["obstacles"] = [
        {
            "name": o.name,
            "centre": list(o.centre),
            "half": list(o.half),
            "yaw": o.yaw,
            "colour": list(o.rgb),
        }
        for o in scene.obstacles
    ]
    out["objects"] = [
        {
            "name": o.name,
            "kind": o.kind,
            "size": o.size[0] if o.kind == "cube" else list(o.size),
            "colour": list(o.rgb),
            "pose": {"xyz": list(o.pose.xyz), "yaw": o.pose.yaw},
        }
        for o in scene.objects
    ]
    if scene.camera is not None:
        c = scene.camera
        out["camera"] = {
            "eye": list(c.eye),
            "target": list(c.target),
            "up": list(c.up),
            "fovy": c.fovy,
            "width": c.width,
            "height": c.height,
        }
    if not scene.parking:
        out["parking"] = False
    return out


def _region_dict(r: Region) -> dict:
    out = {"name": r.name, "min": list(r.lo), "max": list(r.hi)}
    if r.on is not None:
        out["on"] = r.on
    out |= {
        "floor": r.floor,
        "wall_height": r.wall_height,
        "wall_thickness": r.wall_thickness,
        "colour": list(r.rgb),
    }
    return out


def save_scene(scene: Scene, path: str | Path) -> Path:
    """Write ``scene`` as a schema-1 JSON file at ``path``."""
    path = Path(path)
    path.write_text(dumps(scene_dict(scene)))
    return path


def dumps(data: dict) -> str:
    """Scene data as indented JSON with each list of numbers on one line."""
    text = json.dumps(data, indent=2)
    return re.sub(r"\[\s*([-0-9.e,\s]+?)\s*\]", _one_line, text) + "\n"


def _one_line(match: re.Match) -> str:
    return "[" + ", ".join(v.strip() for v in match.group(1).split(",")) + "]"
