"""The outcome vocabulary both stacks report in: `Failure`, what can go wrong when the arm makes
a move, and `EpisodeStatus`, why an episode stopped.

One home below both executors (the Blocksworld loop's `tamp.loop.execute` and the geometric
room's `tamp.geo.check` / `tamp.geo.execute`) and both episodes (`tamp.loop.episode`,
`tamp.geo.episode`), so a failure kind or a status has one name and one spelling (the member's
value) in every report, failure memory and JSON file. It imports nothing of either stack.
"""

from __future__ import annotations

import enum


class Failure(enum.Enum):
    """Why a move failed; each is a replanning trigger. The checks before the arm moves find
    the first seven (the geometric check all of them but ``no_free_slot``; the loop's top-down
    executor ``ik_infeasible``, ``no_clearance``, ``collision`` and ``no_free_slot``); the run
    finds the rest from the robot's own signals (gripper, joint tracking, the observed poses)."""

    NOT_CLEAR = "not_clear"  # something rests on the object to be picked
    UNSUPPORTED = "unsupported"  # the place overlaps something or would not rest on its target
    NO_GRASP = "no_grasp"  # no candidate grasp of the object fits the gripper
    IK_INFEASIBLE = "ik_infeasible"  # a waypoint of the pick-and-place has no IK solution
    NO_CLEARANCE = "no_clearance"  # an overhead obstacle leaves the hand no room at a tower
    COLLISION = "collision"  # a trajectory would hit something, and no detour was found
    NO_FREE_SLOT = "no_free_slot"  # a move to the table found every table slot taken
    GRASP_MISSED = "grasp_missed"  # after closing, the fingers do not hold an object that wide
    DROPPED = "dropped"  # the object left the fingers after the lift
    TRACKING = "tracking_error"  # the arm could not follow its trajectory (blocked)
    MISPLACED = "misplaced"  # after release the block is not where it was to be placed
    UNEXPECTED = "unexpected"  # the facts observed after the move are not those it was to give
    UNOBSERVABLE = "unobservable"  # the camera could not see a block the move needs, from home


class EpisodeStatus(enum.Enum):
    """Why an episode stopped. The geometric episode ends with one of the first five; the
    Blocksworld loop with ``goal_reached``, ``no_plan``, ``replan_budget`` or one of the last
    five (``interrupted``: Ctrl-C, the report carried by `EpisodeInterrupted`). Whether the goal
    holds on ground truth is reported beside the status, never read from it."""

    GOAL_REACHED = "goal_reached"  # the observed state satisfies the goal
    NOT_REACHED = "not_reached"  # the plans ran out, or only the robot saw the goal
    NO_PLAN = "no_plan"  # the task planner found no plan from an observed state
    REPLAN_BUDGET = "replan_budget"  # more failures than ``max_replans``
    MOVE_BUDGET = "move_budget"  # the episode's moves were used up first
    UNREADABLE = "unreadable"  # the observed poses do not form a blocksworld state
    OUT_OF_REACH = "out_of_reach"  # the same move had no IK solution twice in a row
    INVALID_PLAN = "invalid_plan"  # a given plan stopped at a step it could not attempt
    PLAN_ENDED = "plan_ended"  # a given plan ran to its end without reaching the goal
    INTERRUPTED = "interrupted"  # Ctrl-C: the report holds what was done until then


class EpisodeInterrupted(KeyboardInterrupt):
    """Ctrl-C during an episode, with its ``report`` so far (status ``interrupted``). Still a
    KeyboardInterrupt: a benchmark's sweep stops on it as on any Ctrl-C; ``tamp run`` writes
    the report."""

    def __init__(self, report: object) -> None:
        super().__init__("interrupted")
        self.report = report


def time_limit_reached(limit_s: float) -> str:
    """How a ``no_plan`` reason says that the planner's time limit stopped it (both episodes)."""
    return f"time limit ({limit_s:g} s) reached"
