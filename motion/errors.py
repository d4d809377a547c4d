"""Errors about misusing the motion layer: wrong array shapes, bad limits, malformed requests.

Outcomes the loop must react to (an unreachable waypoint) are values, see
`motion.pick_place.MotionResult`; only misuse raises.
"""

from __future__ import annotations

from task.errors import TampError


class MotionError(TampError):
    """An IK target, joint vector, trajectory or request has the wrong shape or values."""
