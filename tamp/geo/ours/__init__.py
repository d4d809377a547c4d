"""The motion-aware planner of scene-file problems ("ours"), on the differentiable planner.

A scene and its goal become a Blocksworld problem on capacity-one places whose region cells
are placed jointly by gradient (`tamp.geo.ours.pack`, `tamp.geo.ours.bridge`); the planner
(`task.planner.plan`, receding windows then its complete lazy fallback) prices every move with
the arm (`tamp.geo.ours.costs.GeoCosts`: IMPOSSIBLE without a free grasp at both ends, else
the joint distance); each planned move is bound to a grasp by the full check
(`tamp.geo.check.check_move`), refusals come back as failure memory and the problem is planned
again (`tamp.geo.ours.planner`). A problem named by a PDDL domain (Tower of Hanoi) is planned
through the generic lift and its declared binding instead.

- `tamp.geo.ours.pack`: gradient-optimised placements in a region, and the sampled baseline;
- `tamp.geo.ours.bridge`: scene + goal -> Blocksworld on places, and planned moves back;
- `tamp.geo.ours.costs`: `GeoCosts`, the arm's price of every move, with failure memory;
- `tamp.geo.ours.cells`: the empty cells as variables of the planner's Adam, per restart row;
- `tamp.geo.ours.placing`: the opening moves into position, taken without a window;
- `tamp.geo.ours.planner`: `plan_motion_aware`, `plan_pddl`, `OursConfig`, and the ablation
  `plan_motion_aware_sampled` (cells placed by rejection sampling).
"""

from tamp.geo.ours.planner import (
    PLANNER,
    OursConfig,
    as_ours,
    plan_motion_aware,
    plan_motion_aware_sampled,
    plan_pddl,
)

__all__ = [
    "PLANNER",
    "OursConfig",
    "as_ours",
    "plan_motion_aware",
    "plan_motion_aware_sampled",
    "plan_pddl",
]
