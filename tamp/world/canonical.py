"""The field's canonical TAMP problems as scenes: seeded generators of variants, shipped at seed 0.

Six problems (`PROBLEMS`), each a `tamp.world.schema.Scene` and a `tamp.world.goal.Goal` in our
world (the Panda at the origin facing +x, the table top at z = 0, metres and radians):

- ``blocked`` (PDDLStream's *blocked*): the target ``t`` hemmed in by 3 or 4 neighbours 4-8 mm
  away on its sides; the goal names only the target, ``(in t goal_zone)``;
- ``packed`` (PDDLStream's *packed*, cuTAMP's packing): 4-6 boxes into the marked area ``tray``
  that holds them only in two columns with a finger lane between them;
- ``nonmonotonic`` (Lagriffoul et al. 2018, problem 4): the target ``t`` at the back of an
  alcove behind 2-3 front objects that must go out and come back;
- ``sorting`` (Lagriffoul problem 3): 4-8 objects of 2-3 colours among posts, each to its
  colour's zone;
- ``tall``: a tower of 8-10 cubes built or taken down at the edge of the arm's reach;
- ``hanoi``: Tower of Hanoi, 3-5 square discs on three pegs (marked regions that hold one
  tower each), played by its rules: nothing is parked on the bare table (`NO_PARKING`); a
  disc stands only on a wider one, as the geometry says; `hanoi_pddl` writes the problem for
  ``task/data/hanoi.pddl`` from the geometry.

`generate(problem, seed, **size)` draws a variant from ``numpy.random.default_rng(seed)``
(positions, yaws, colours, counts); every variant passes `tamp.world.load.load_scene`'s checks
(it is round-tripped through `scene_dict`), keeps its objects within the arm's reach and has a
goal the initial state does not meet. `write_all` writes the seed-0 variants to
``tamp/world/scenes/canonical/<name>.json`` and ``<name>.goal.pddl``; `shipped` reads them back.

What makes each problem hard is geometric, and `free_top_axes` (`tamp.world.hand`, the reference
model of the open hand) measures it: which top-down closing axes of an object are free of
everything else. The generators (`tamp.world.generators`) draw until the intended axes are free
or blocked (with a margin), and the tests check the same. The names of both modules stay
importable from here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from tamp.scene import Pose
from tamp.sim.base import Camera
from tamp.world.generators import (
    COLOURS,
    GENERATORS,
    KERB,
    POST_HALF,
    TABLE_TOP,
    TRIES,
    centre_first,
    round_length,
)
from tamp.world.geometry import of_movable
from tamp.world.goal import Goal, parse_goal
from tamp.world.hand import (
    APPROACH,
    FINGER_ACROSS,
    FINGER_IN,
    FINGER_OUT,
    FINGER_TIP,
    PALM_ABOVE,
    PALM_ACROSS,
    PALM_ALONG,
    REACH_EDGE,
    free_top_axes,
    top_grasp_heights,
    top_reach,
)
from tamp.world.load import dumps, load_scene, scene_dict
from tamp.world.relations import read_facts
from tamp.world.schema import Movable, Region, Scene
from task.errors import ProblemError, one_of

__all__ = [  # re-exported from `tamp.world.hand` and `tamp.world.generators`, plus our own
    "APPROACH",
    "COLOURS",
    "FINGER_ACROSS",
    "FINGER_IN",
    "FINGER_OUT",
    "FINGER_TIP",
    "KERB",
    "PALM_ABOVE",
    "PALM_ACROSS",
    "PALM_ALONG",
    "POST_HALF",
    "PROBLEMS",
    "REACH_EDGE",
    "SCENES_DIR",
    "SIZES",
    "TABLE_TOP",
    "TRIES",
    "CanonicalProblem",
    "centre_first",
    "free_top_axes",
    "generate",
    "hanoi_pddl",
    "in_view",
    "shipped",
    "top_grasp_heights",
    "top_reach",
    "write_all",
]

PROBLEMS = ("blocked", "packed", "nonmonotonic", "sorting", "tall", "hanoi")
SCENES_DIR = Path(__file__).resolve().parent / "scenes" / "canonical"

SIZES = {  # the keyword arguments each problem takes: name -> (low, high) or choices
    "blocked": {"n": (3, 4)},
    "packed": {"n": (4, 6)},
    "nonmonotonic": {"n": (2, 3)},
    "sorting": {"n": (4, 8), "colours": (2, 3)},
    "tall": {"n": (8, 10), "mode": ("build", "down")},
    "hanoi": {"n": (3, 5)},
}


@dataclass(frozen=True)
class CanonicalProblem:
    """One variant of a canonical problem: its scene, its goal and one line on why it is hard.

    ``witness``: for ``packed``, poses (name, pose) of every object in the tray that meet the
    goal, each with a free top-down grasp among the others: the goal is reachable. Empty for
    the other problems. ``domain``: for a problem defined by a PDDL domain (``hanoi``), the
    domain's text and its binding to the motion layer (`task.symbolic.pickplace.binding`),
    for a planner that plans through it; None for the others.
    """

    name: str
    seed: int
    scene: Scene
    goal: Goal
    note: str
    witness: tuple[tuple[str, Pose], ...] = ()
    domain: tuple[str, str] | None = None

    def goal_text(self) -> str:
        """The goal as a goal file: a comment with the note, then the formula, one atom a line."""
        atoms = "\n".join(f"  ({' '.join(a)})" for a in self.goal.atoms)
        return f"; {self.name}, seed {self.seed}: {self.note}\n(and\n{atoms})\n"


def generate(problem: str, seed: int, **size) -> CanonicalProblem:
    """The variant ``seed`` of ``problem`` (one of `PROBLEMS`); ``size`` overrides what is
    drawn: ``n`` (the count of the problem's objects) for every problem, ``colours`` for
    sorting, ``mode`` (``build`` or ``down``) for tall; see `SIZES` for the ranges."""
    if problem not in PROBLEMS:
        raise ProblemError(f"unknown canonical problem {one_of(problem, PROBLEMS)}")
    valid = SIZES[problem]
    for key, value in size.items():
        if key not in valid:
            raise ProblemError(f"{problem}: unknown size {one_of(key, sorted(valid))}")
        allowed = valid[key]
        if isinstance(allowed[0], str):
            if value not in allowed:
                raise ProblemError(f"{problem}: {key} {one_of(value, allowed)}")
        elif isinstance(value, bool) or not (
            isinstance(value, int) and allowed[0] <= value <= allowed[1]
        ):
            raise ProblemError(
                f"{problem}: {key} must be a whole number in {allowed[0]}..{allowed[1]}, "
                f"got {value!r}"
            )
    rng = np.random.default_rng(seed)
    drawn = {
        key: (str(rng.choice(v)) if isinstance(v[0], str) else int(rng.integers(v[0], v[1] + 1)))
        for key, v in valid.items()
    }
    drawn |= size
    make = GENERATORS[problem]
    for _ in range(TRIES):
        made = make(rng, **drawn)
        if made is not None:
            break
    else:
        raise ProblemError(f"{problem}: no variant found for seed {seed} in {TRIES} draws")
    return _finish(problem, seed, _Drawn(*made))


def write_all(directory: str | Path = SCENES_DIR) -> tuple[Path, ...]:
    """Write every problem's seed-0 variant to ``directory``: ``<name>.json`` (the scene) and
    ``<name>.goal.pddl`` (the goal); the paths written."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for name in PROBLEMS:
        p = generate(name, 0)
        scene_path = directory / f"{name}.json"
        scene_path.write_text(dumps(scene_dict(p.scene)))
        goal_path = directory / f"{name}.goal.pddl"
        goal_path.write_text(p.goal_text())
        out += [scene_path, goal_path]
    return tuple(out)


def shipped(problem: str) -> tuple[Scene, Goal]:
    """The shipped seed-0 scene and goal of ``problem``, read from `SCENES_DIR`."""
    if problem not in PROBLEMS:
        raise ProblemError(f"unknown canonical problem {one_of(problem, PROBLEMS)}")
    scene = load_scene(SCENES_DIR / f"{problem}.json")
    path = SCENES_DIR / f"{problem}.goal.pddl"
    return scene, parse_goal(path.read_text(), scene, source=f"goal file {path}")


# ---- Hanoi as PDDL ---------------------------------------------------------------------------


def hanoi_pddl(problem: CanonicalProblem) -> str:
    """The problem PDDL of ``problem``'s scene and goal for ``task/data/hanoi.pddl``
    (``hanoi-pick-place``): its objects are the discs, its regions the pegs; ``smaller`` from
    the discs' widths (every disc is smaller than every peg); the initial state read from the
    geometry (`read_facts`), ``(in d peg)`` written ``(on d peg)``. ProblemError when a disc
    rests elsewhere than on a peg or a disc, or the goal names another predicate."""
    from task.symbolic.pickplace.hanoi import DOMAIN  # crisp, light; only Hanoi needs it

    scene = problem.scene
    facts = read_facts(scene)
    if facts.unexplained:
        raise ProblemError(f"hanoi: {facts.issues[0]}")
    width = {o.name: o.width for o in scene.objects}
    discs = sorted(width, key=lambda d: (width[d], d))
    pegs = [r.name for r in scene.regions]
    init = sorted(_hanoi_atom(a, "initial state") for a in facts.atoms if a[0] != "clear")
    held = {a[2] for a in init}
    clear = [d for d in discs if ("clear", d) in facts.atoms] + [p for p in pegs if p not in held]
    smaller = [f"(smaller {a} {b})" for a in discs for b in discs if width[a] < width[b]]
    smaller += [f"(smaller {d} {p})" for d in discs for p in pegs]
    goal = [_hanoi_atom(a, "goal") for a in problem.goal.atoms]
    lines = [
        f"(define (problem {scene.name}) (:domain {DOMAIN})",
        f"  (:objects {' '.join(discs)} - disc {' '.join(pegs)} - peg)",
        "  (:init",
        *(f"    (on {a[1]} {a[2]})" for a in init),
        *(f"    (clear {x})" for x in clear),
        *(f"    {a}" for a in smaller),
        "  )",
        f"  (:goal (and {' '.join(f'(on {a[1]} {a[2]})' for a in goal)})))",
    ]
    return "\n".join(lines) + "\n"


def _hanoi_atom(atom: tuple[str, ...], where: str) -> tuple[str, ...]:
    if atom[0] not in ("on", "in"):
        raise ProblemError(
            f"hanoi: {where} holds ({' '.join(atom)}); discs rest on a disc or a peg only"
        )
    return ("on", atom[1], atom[2])


# ---- the checked scene ------------------------------------------------------------------------


def _camera(objects: Sequence[Movable], regions: Sequence[Region]) -> Camera:
    """A camera from the default's direction (front right, above) at the distance that fits
    every object and region in its view with a margin."""
    default = Camera()
    pts = []
    for o in objects:
        for cx, cy in of_movable(o).corners():
            pts += [(cx, cy, o.bottom), (cx, cy, o.top)]
    for r in regions:
        pts += [(x, y, r.surface) for x in (r.lo[0], r.hi[0]) for y in (r.lo[1], r.hi[1])]
    p = np.asarray(pts)  # (P, 3)
    lo, hi = p.min(0), p.max(0)
    target = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.4 * hi[2]])
    away = np.subtract(default.eye, default.target)
    away /= np.linalg.norm(away)
    for d in np.arange(0.6, 4.0, 0.05):
        eye = target + d * away
        if in_view(p, eye, target, default, margin=0.9):
            break
    return Camera(tuple(round_length(v) for v in eye), tuple(round_length(v) for v in target))


def in_view(points, eye, target, camera: Camera = Camera(), margin: float = 1.0) -> bool:
    """True when every point of ``points`` (P, 3) projects inside the pinhole image of a camera
    at ``eye`` looking at ``target`` (``camera``'s fovy, up and aspect), within ``margin`` of
    the half field of view."""
    f = np.subtract(target, eye)
    f = f / np.linalg.norm(f)
    right = np.cross(f, camera.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    v = np.asarray(points, dtype=float) - np.asarray(eye)  # (P, 3)
    depth = v @ f  # (P,)
    ty = math.tan(math.radians(camera.fovy) / 2) * margin
    tx = ty * camera.width / camera.height
    return bool(
        (depth > 0).all()
        and (np.abs(v @ up) <= ty * depth).all()
        and (np.abs(v @ right) <= tx * depth).all()
    )


# problems played by their rules: Tower of Hanoi's discs rest only on pegs and discs, never
# parked on the bare table (`tamp.world.schema.Scene.parking`)
NO_PARKING = frozenset({"hanoi"})


class _Drawn(NamedTuple):
    """What a generator (`GENERATORS`) draws: the scene's parts, the goal atoms, the note and
    the witness plan."""

    objects: Sequence
    regions: Sequence
    obstacles: Sequence
    atoms: Sequence[tuple[str, ...]]
    note: str
    witness: Sequence


def _finish(name, seed, drawn: _Drawn) -> CanonicalProblem:
    """The ``drawn`` variant as a checked scene: round-tripped through the file format and the
    loader's checks (a failure here is a generator bug), its goal parsed and unmet."""
    objects, regions, obstacles, atoms, note, witness = drawn
    scene = Scene(
        f"{name}-{seed}",
        TABLE_TOP,
        tuple(regions),
        tuple(obstacles),
        tuple(objects),
        None,
        _camera(objects, regions),
        parking=name not in NO_PARKING,
    )
    scene = load_scene(scene_dict(scene))
    text = "(and " + " ".join(f"({' '.join(a)})" for a in atoms) + ")"
    goal = parse_goal(text, scene, source=f"{name} goal")
    if goal.holds(read_facts(scene)):
        raise ProblemError(f"{name}: seed {seed} draws a scene that already meets its goal")
    domain = None
    if name == "hanoi":
        from task.symbolic.pickplace import hanoi

        domain = (hanoi.domain_text(), hanoi.BINDING)
    return CanonicalProblem(name, seed, scene, goal, note, tuple(witness), domain)
