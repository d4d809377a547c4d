"""The episode's scoring: the experimenter's look at simulator ground truth, never the robot's.

`Scorer` is the one place in the loop that reads ``sim.truth``, and only inside
``GroundTruth.scoring()``: the true symbolic state before and after each move (to count moves
that disturbed another stack) and at the end (did the episode reach the PDDL goal?). Nothing it
learns flows back into what the robot does; the episode locks the ground truth so that any
other read raises `tamp.sim.truth.GroundTruthLeak`.

A move is scored `MoveScore.CLEAN` only when the true state can be read before and after it
and no other block changed support. A true state that forms no blocksworld state (a tower
knocked into a leaning pile, a block left across two others) cannot show that the move was
clean, so it counts against the plan: `MoveScore.UNREADABLE`, reported as its own count.
"""

from __future__ import annotations

import enum

from tamp.scene import SceneConfig
from tamp.sim.truth import GroundTruth
from tamp.world.convert.from_poses import read_state
from task.domains.base import Domain, State
from task.problem import Move, Problem


class MoveScore(enum.Enum):
    """What one move did to the other blocks, on ground truth."""

    CLEAN = "clean"  # every other block kept its true support
    DISTURBED = "disturbed"  # another block's true support changed
    UNREADABLE = "unreadable"  # the true state before or after forms no state: not shown clean


class Scorer:
    """Scores one episode of ``problem`` on ``truth`` (the simulator's ground truth)."""

    def __init__(self, truth: GroundTruth, problem: Problem, scene: SceneConfig) -> None:
        self.truth, self.problem, self.scene = truth, problem, scene

    def state(self) -> State | None:
        """The true symbolic state (None when the blocks form none, e.g. one leans)."""
        with self.truth.scoring():
            poses = self.truth.block_poses()
        return read_state(self.problem.entities, poses, self.scene).state

    def reached(self, domain: Domain) -> bool:
        """The true state satisfies the problem's own (PDDL) goal."""
        truth = self.state()
        return truth is not None and domain.is_goal(self.problem, truth)

    def move(self, move: Move, before: State | None) -> MoveScore:
        """Score ``move`` now that it is done, from the true state ``before`` it (`state`):
        DISTURBED when a block other than the moved one has another true support, UNREADABLE
        when either state is unreadable, else CLEAN."""
        after = self.state()
        if before is None or after is None:
            return MoveScore.UNREADABLE
        entities = self.problem.entities
        if any(x != move.entity and before[i] != after[i] for i, x in enumerate(entities)):
            return MoveScore.DISTURBED
        return MoveScore.CLEAN
