"""The reference open hand: which top-down grasps of an object are free of everything else.

`free_top_axes` measures what makes the canonical problems (`tamp.world.canonical`) hard with a
reference model of the open hand (the boxes of `motion.grasps`: fingers 4.2-6.6 cm either side of
the grasp axis, 2 cm across, from 8 mm below the TCP up; the palm 20.4 x 6 cm from 4 cm above the
TCP, which sits where `motion.grasps.grasps` puts it: at the centre, at most 2.5 cm below the
top): which top-down closing axes of an object are free of everything else. `top_reach` is the
arm's top-down reach at the edge of its workspace.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

from motion.grasps import HAND_BOXES, grasps
from tamp.world.geometry import Solid, fixed_solids, footprint_gap, of_movable
from tamp.world.schema import Movable, Scene

# The reference open hand, top-down, in the grasp frame (closing axis, across, z up from the
# TCP): the boxes of `motion.grasps.HAND_BOXES` (pybullet_data's Panda, fingers fully open);
# where the TCP sits on an object and which faces fit between the fingers come from
# `motion.grasps.grasps`' top grasps.
_PALM, _FINGER = HAND_BOXES[0], HAND_BOXES[1]
FINGER_IN = _FINGER[0][1] - _FINGER[1][1]  # m, an open finger's inner face from the grasp axis
FINGER_OUT = _FINGER[0][1] + _FINGER[1][1]  # m, its outer face
FINGER_ACROSS = _FINGER[1][0]  # m, half its width across the closing axis
FINGER_TIP = _FINGER[0][2] + _FINGER[1][2]  # m, the fingertips below the TCP
PALM_ABOVE = -(_PALM[0][2] + _PALM[1][2])  # m, the palm's lowest face above the TCP
PALM_ALONG = _PALM[1][1]  # m, half the palm's length along the closing axis
PALM_ACROSS = _PALM[1][0]  # m, half its thickness across

# Top-down reach at the edge (`motion.ik.IKSolver`, TCP pointing down, from the home pose): the
# highest reachable TCP falls from 0.58 m at 0.64 m out to 0.46 m at 0.72 m, about linearly.
REACH_EDGE = (0.64, 0.58, 1.5)  # (radius m, highest TCP z m there, drop per m farther out)
APPROACH = 0.10  # m, the pre-grasp above an object's top (`motion.pick_place`)


# ---- the hand's reference model ----------------------------------------------------------------


def top_grasp_heights(o: Movable) -> dict[int, float]:
    """Closing axis (0: the object's x, 1: its y) -> z (m) of the TCP, for each top-down grasp
    `motion.grasps.grasps` offers for ``o`` (its face between the fingers fits the stroke;
    the TCP at the centre, at most 2.5 cm below the top, the fingertips clear of the bottom)."""
    return {axis: o.pose.xyz[2] + dz for axis, dz in _top_offsets(o.kind, o.half)}


@functools.lru_cache(maxsize=4096)
def _top_offsets(kind: str, half: tuple[float, float, float]) -> tuple[tuple[int, float], ...]:
    """(closing axis, TCP height over the centre m) of each top grasp of a ``kind``, ``half``."""
    out = {}
    for g in grasps(kind, half, ("top",)):
        axis = 0 if int(g.name.removeprefix("top")) % 2 else 1  # even k close along y
        out[axis] = g.tcp[2][3]
    return tuple(sorted(out.items()))


def free_top_axes(
    scene: Scene, name: str, pad: float = 0.0, without: Sequence[str] = ()
) -> tuple[int, ...]:
    """The closing axes (0: the object's x, 1: its y) along which a top-down grasp of object
    ``name`` fits: `motion.grasps` offers it (`top_grasp_heights`) and the reference open
    hand (module docstring) touches nothing else: no solid taller than the fingertips meets a
    finger's footprint (swept in to the object's face), none taller than the palm's lower face
    meets the palm's. ``pad`` (m) grows the hand's footprints (negative: shrinks them);
    ``without`` names objects to leave out (as if moved away)."""
    o = scene.object(name)
    others = [of_movable(x) for x in scene.objects if x.name != name and x.name not in without]
    others += fixed_solids(scene)
    reach = math.hypot(PALM_ALONG, PALM_ACROSS) + abs(pad)  # nothing farther can touch the hand
    others = [
        s
        for s in others
        if math.dist(s.centre[:2], o.pose.xyz[:2]) <= reach + math.hypot(s.half[0], s.half[1])
    ]
    free = []
    for axis, z in sorted(top_grasp_heights(o).items()):
        hand = _hand(o, axis, z, pad)
        if all(
            footprint_gap(part, s) > 0.0 for part, floor in hand for s in others if s.top > floor
        ):
            free.append(axis)
    return tuple(free)


def _hand(o: Movable, axis: int, z: float, pad: float) -> list[tuple[Solid, float]]:
    """The open hand's footprints for a top-down grasp of ``o`` closing along ``axis``, each
    with the height of its lowest point: two fingers (from the object's face to their outer
    face) and the palm."""
    yaw = o.pose.yaw + axis * math.pi / 2  # the closing axis's direction
    u = (math.cos(yaw), math.sin(yaw))
    x, y = o.pose.xyz[0], o.pose.xyz[1]
    face = min(o.half[axis], FINGER_IN)
    mid, half = (face + FINGER_OUT) / 2, (FINGER_OUT - face) / 2
    parts = [
        (
            Solid(
                "finger",
                False,
                (x + s * mid * u[0], y + s * mid * u[1], z),
                (half + pad, FINGER_ACROSS + pad, 0.0),
                yaw,
            ),
            z - FINGER_TIP,
        )
        for s in (1.0, -1.0)
    ]
    palm = Solid("palm", False, (x, y, z), (PALM_ALONG + pad, PALM_ACROSS + pad, 0.0), yaw)
    return [*parts, (palm, z + PALM_ABOVE)]


def top_reach(radius: float) -> float:
    """The highest top-down TCP z (m) the arm reaches at ``radius`` m from its base axis, at the
    edge of its reach (`REACH_EDGE`, measured from 0.64 to 0.72 m)."""
    r0, z0, slope = REACH_EDGE
    return z0 - slope * (radius - r0)
