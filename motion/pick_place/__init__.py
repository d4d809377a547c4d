"""One move of an upright object by the arm: its plan and the corrections made while it runs.

- `plan` (`plan_pick_place`): six TCP waypoints solved by IK, eight phases (approach, descend,
  close, lift, transit, lower, open, retreat) of jerk-limited joint trajectories;
- `lines` (`vertical_path`): the vertical phases as joint paths that keep the hand on its
  straight line, or none where no IK branch does;
- `correct` (`corrected_place`, `split_lower`): the place side moved by where the object sits
  in the hand, the lower cut where the hand stops to look.
"""

from motion.pick_place.correct import corrected_place, split_lower
from motion.pick_place.plan import (
    PHASES,
    WAYPOINTS,
    MotionResult,
    Phase,
    PickPlaceConfig,
    PickPlaceRequest,
    plan_pick_place,
    request_grasp,
    waypoint_targets,
)

__all__ = [
    "PHASES",
    "WAYPOINTS",
    "MotionResult",
    "Phase",
    "PickPlaceConfig",
    "PickPlaceRequest",
    "corrected_place",
    "plan_pick_place",
    "request_grasp",
    "split_lower",
    "waypoint_targets",
]
