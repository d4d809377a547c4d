"""Grasps as choices: how the hand may hold an upright object, each a TCP pose in its frame.

An object's frame has its origin at the object's centre, z up, x and y along its faces (turned
by the object's yaw about the world z); ``half`` = (hx, hy, hz) are its half extents there (a
cylinder: (r, r, h / 2)). A `Grasp` is the TCP (``panda_grasptarget``) pose in that frame, the
direction the hand comes in along to reach it, and the object's width between the fingers.
`world_tcp` turns a grasp and an object pose into the TCP pose in the base frame.

The TCP frame (the Panda's): z points out of the palm between the fingers (the approach), y is
the axis the fingers close along, x = y cross z. Measured in that frame (pybullet_data URDF,
fingers open): the palm spans x +-0.03, y +-0.10, z [-0.132, -0.040] m; each finger x +-0.01,
z [-0.044, +0.008] (the fingertips 8 mm past the TCP), its inner face at y = +-opening.

`grasps(kind, half, choices)` lists the candidates of three families:

- ``top0`` .. ``top3``: pointing down, hand yaw k pi/2 in the object frame (tool x = Rz(k pi/2)
  e_x, R = Rz(k pi/2) Rx(pi), `motion.ik.top_down_pose`'s convention), so the fingers close
  along the object's y for even k and its x for odd k. The TCP sits on the vertical axis at
  ``GRASP_DEPTH`` below the top, but never below the centre: a 5 cm cube is held at its centre
  (``top0`` of a cube is exactly today's top-down grasp), a tall object by its upper part with
  the palm 1.5 cm above its top; an object under 5 cm tall as far down as keeps the
  fingertips ``FINGER_CLEARANCE`` above its bottom (offered while the TCP stays
  ``PAD_OVERLAP`` below its top: from 1.8 cm tall).
- ``side+x``, ``side-x``, ``side+y``, ``side-y``: the hand horizontal, coming from the named
  side n (approach -n), tool x up, the fingers closing horizontally across the other
  horizontal axis. The TCP is ``GRASP_DEPTH`` inside the face n (at most to the centre), at
  the centre height, raised where the object is short so that the palm (3 cm below the TCP)
  stays ``SIDE_CLEARANCE`` above the object's bottom (its support); offered only where the
  TCP then stays ``PAD_OVERLAP`` below the top. Whether the wrist behind the palm clears what
  is around is for the collision check, not this generator.
- ``tilt+x`` .. ``tilt-y``: the side grasp pitched 45 deg towards vertical: coming from side n
  and above (approach (-n - e_z) / sqrt 2), fingers across the other horizontal axis, tool x
  up and outwards, the TCP ``GRASP_DEPTH`` in from the middle of the top edge on side n along
  the approach.
- each side and tilted grasp also comes turned a half turn about its approach (name suffix
  ``:flip``, tool x down or down-outwards): the same hold with the fingers swapped, as
  ``top2`` is ``top0`` turned. Joint 7 cannot always turn that far (a hand pointing straight
  away from the robot reaches only with tool x down), so both are choices.

Every grasp needs the object's width between the fingers to leave more than ``FINGER_SPARE``
on each side of the 0.08 m stroke (a 7 cm face is too wide), and the open hand at the grasp
to stay ``FINGER_CLEARANCE`` above the object's bottom. A cylinder looks the same at every
yaw: its top grasps are ``top0`` and ``top1`` (a quarter turn apart, so one of them is within
pi/4 of any hand yaw modulo the gripper's half-turn symmetry); its side and tilted grasps are
the four directions as for a box (the same geometry, four approach directions in the world).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from motion.errors import MotionError
from task.errors import one_of

KINDS = ("cube", "cuboid", "cylinder")
FAMILIES = ("top", "side", "tilt")
STROKE = 0.08  # m, the gripper's widest opening (two fingers of 0.04 m)
FINGER_SPARE = 0.005  # m, each open finger must clear the object by more than this
GRASP_DEPTH = 0.025  # m, the TCP at most this far inside the face it comes through
SIDE_CLEARANCE = 0.015  # m, a side grasp's palm above the object's bottom (approach margin)
FINGER_CLEARANCE = 0.005  # m, the open hand's lowest point above the object's bottom
PAD_OVERLAP = 0.005  # m, a side grasp's TCP at least this far below the object's top
# the open hand in the TCP frame: (centre, half extents) boxes of the palm and the fingers
HAND_BOXES = (
    ((0.0, 0.0, -0.086), (0.03, 0.102, 0.046)),
    ((0.0, 0.054, -0.018), (0.01, 0.012, 0.026)),
    ((0.0, -0.054, -0.018), (0.01, 0.012, 0.026)),
)
SIDES = {"+x": (1.0, 0.0), "-x": (-1.0, 0.0), "+y": (0.0, 1.0), "-y": (0.0, -1.0)}
ROLLS = (("", 1.0), (":flip", -1.0))  # a side or tilted hand as is, or turned a half turn


@dataclass(frozen=True)
class Grasp:
    """How the hand holds an object.

    ``name``: e.g. ``"top0"`` .. ``"top3"`` (top-down, hand yaw k pi/2 in the object frame),
    ``"side+x"`` (from the object's +x side, hand horizontal), ``"tilt+x"``, ``"side+x:flip"``.
    ``tcp``: (4, 4) TCP pose in the object frame, as nested tuples (row-major).
    ``approach``: unit vector in the object frame along which the TCP moves in to the grasp
    (top-down: (0, 0, -1)); the hand backs out along its opposite.
    ``width``: m, the object's extent between the fingers (at most the stroke, 0.08 m).
    """

    name: str
    tcp: tuple[tuple[float, ...], ...]
    approach: tuple[float, float, float]
    width: float

    @property
    def matrix(self) -> np.ndarray:
        """The (4, 4) TCP pose in the object frame."""
        return np.asarray(self.tcp, dtype=np.float64)


def object_frame(xyz, yaw: float) -> np.ndarray:
    """(4, 4) pose of an upright object's frame: its centre ``xyz`` (m), turned ``yaw`` (rad)."""
    c, s = math.cos(yaw), math.sin(yaw)
    h = np.eye(4)
    h[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    h[:3, 3] = np.asarray(xyz, dtype=np.float64)
    return h


def world_tcp(grasp: Grasp, xyz, yaw: float) -> np.ndarray:
    """(4, 4) TCP pose in the base frame holding the object at centre ``xyz``, yaw ``yaw``."""
    return object_frame(xyz, yaw) @ grasp.matrix


def world_approach(grasp: Grasp, yaw: float) -> np.ndarray:
    """(3,) the grasp's approach direction in the base frame for an object turned ``yaw``."""
    return object_frame((0.0, 0.0, 0.0), yaw)[:3, :3] @ np.asarray(grasp.approach)


def back_out(grasp: Grasp, half) -> float:
    """m the TCP moves back along -approach from the grasp until it leaves the object's box
    (``half`` (3,) half extents): for a top grasp, from the TCP up to the top face."""
    t, a, h = grasp.matrix[:3, 3], np.asarray(grasp.approach), np.asarray(half, dtype=float)
    moving = np.abs(a) > 1e-9
    # the point t - s a crosses the face where |t_i - s a_i| = h_i first
    s = (h[moving] + np.sign(a[moving]) * t[moving]) / np.abs(a[moving])  # (<=3,)
    return max(float(s.min()), 0.0)


def _grasp(name: str, approach, closing, tcp_xyz, width: float) -> Grasp:
    """The grasp with TCP z = ``approach``, y = ``closing`` (unit, orthogonal), at ``tcp_xyz``."""
    z, y = np.asarray(approach, dtype=float), np.asarray(closing, dtype=float)
    h = np.eye(4)
    h[:3, :3] = np.stack([np.cross(y, z), y, z], axis=1)  # columns x, y, z
    h[:3, 3] = tcp_xyz
    rows = tuple(tuple(float(v) + 0.0 for v in row) for row in h)  # + 0.0: no -0.0
    return Grasp(name, rows, tuple(float(v) + 0.0 for v in z), float(width))


def _lowest(grasp: Grasp) -> float:
    """The lowest z (object frame) of the open hand's boxes (`HAND_BOXES`) at the grasp."""
    m = grasp.matrix
    corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T  # (8, 3)
    low = math.inf
    for centre, half in HAND_BOXES:
        pts = np.asarray(centre) + corners * np.asarray(half)  # (8, 3) in the TCP frame
        low = min(low, float((pts @ m[:3, :3].T + m[:3, 3])[:, 2].min()))
    return low


def _fits(width: float) -> bool:
    """More than FINGER_SPARE on each side of the object between the open fingers (1 um)."""
    return width + 2 * FINGER_SPARE < STROKE - 1e-6


def _top(hx: float, hy: float, hz: float, ks) -> list[Grasp]:
    out = []
    tip = HAND_BOXES[1][0][2] + HAND_BOXES[1][1][2]  # the fingertips past the TCP
    depth = max(0.0, hz - GRASP_DEPTH, -hz + FINGER_CLEARANCE + tip)  # TCP over the centre
    if depth > hz - PAD_OVERLAP + 1e-9:
        return out  # too flat: the fingertips would reach its support
    for k in ks:
        c, s = math.cos(k * math.pi / 2), math.sin(k * math.pi / 2)
        closing = (s, -c, 0.0)  # tool y of Rz(k pi/2) Rx(pi)
        width = 2 * (hy if k % 2 == 0 else hx)
        out.append(_grasp(f"top{k}", (0.0, 0.0, -1.0), closing, (0.0, 0.0, depth), width))
    return out


def _side(hx: float, hy: float, hz: float) -> list[Grasp]:
    out = []
    palm = HAND_BOXES[0][1][0]  # the palm's half thickness along tool x (vertical here)
    z = max(0.0, -hz + palm + SIDE_CLEARANCE)  # TCP height over the centre
    if z > hz - PAD_OVERLAP + 1e-9:
        return out  # too short: the palm would sweep its support
    for (side, (nx, ny)), (roll, sign) in itertools.product(SIDES.items(), ROLLS):
        inward = max(0.0, (hx if nx else hy) - GRASP_DEPTH)  # TCP from the centre towards n
        approach = (-nx, -ny, 0.0)
        closing = sign * np.cross(approach, (0.0, 0.0, 1.0))  # horizontal; tool x up (sign 1)
        width = 2 * (hy if nx else hx)
        tcp = (nx * inward, ny * inward, z)
        out.append(_grasp(f"side{side}{roll}", approach, closing, tcp, width))
    return out


def _tilt(hx: float, hy: float, hz: float) -> list[Grasp]:
    out = []
    r = 1 / math.sqrt(2)
    for (side, (nx, ny)), (roll, sign) in itertools.product(SIDES.items(), ROLLS):
        approach = np.array([-nx * r, -ny * r, -r])
        closing = sign * np.cross((-nx, -ny, 0.0), (0.0, 0.0, 1.0))
        edge = np.array([nx * hx, ny * hy, hz])  # middle of the top edge on side n
        width = 2 * (hy if nx else hx)
        tcp = edge + GRASP_DEPTH * approach
        out.append(_grasp(f"tilt{side}{roll}", approach, closing, tcp, width))
    return out


def grasps(kind: str, half, choices: tuple[str, ...] = FAMILIES) -> tuple[Grasp, ...]:
    """The candidate grasps of an upright object of ``kind`` (one of `KINDS`) with half
    extents ``half`` (3,) m (see the module docstring), in the order top, side, tilt, of the
    families named in ``choices`` (a subset of `FAMILIES`); those that do not fit the gripper
    or would put the open hand within ``FINGER_CLEARANCE`` of the object's bottom are left
    out, so the result may be empty."""
    if kind not in KINDS:
        raise MotionError(f"unknown object kind {one_of(kind, KINDS)}")
    bad = [c for c in choices if c not in FAMILIES]
    if bad or isinstance(choices, str):
        raise MotionError(f"unknown grasp family {one_of(bad[0] if bad else choices, FAMILIES)}")
    try:
        hx, hy, hz = (float(v) for v in half)
    except (TypeError, ValueError):
        raise MotionError(f"half = {half!r}; expected three half extents (x, y, z) in m") from None
    if not all(math.isfinite(v) and v > 0 for v in (hx, hy, hz)):
        raise MotionError(f"half = {half!r}; expected three finite half extents > 0 m")
    made = {
        "top": _top(hx, hy, hz, range(2) if kind == "cylinder" else range(4)),
        "side": _side(hx, hy, hz),
        "tilt": _tilt(hx, hy, hz),
    }
    return tuple(
        g
        for family in FAMILIES
        if family in choices
        for g in made[family]
        if _fits(g.width) and _lowest(g) >= -hz + FINGER_CLEARANCE - 1e-9
    )
