"""The episode's scoring: the experimenter's look at simulator ground truth, never the robot's.

`Scorer` is the one place in the loop that reads ``sim.truth``, and only inside
``GroundTruth.scoring()``: the true symbolic state before and after each move (to count moves
that disturbed another stack) and at the end (did the episode reach the PDDL goal?). Nothing it
learns flows back into what the robot does; the episode locks the ground truth so that any
other read raises `tamp.sim.truth.GroundTruthLeak`.
"""

from __future__ import annotations

from tamp.scene import SceneConfig
from tamp.sim.truth import GroundTruth
from task.domains.base import Domain, State
from task.problem import Move, Problem


class Scorer:
    """Scores one episode of ``problem`` on ``truth`` (the simulator's ground truth)."""

    def __init__(self, truth: GroundTruth, problem: Problem, scene: SceneConfig) -> None:
        self.truth, self.problem, self.scene = truth, problem, scene

    def state(self) -> State | None:
        """The true symbolic state (None when the blocks form none, e.g. one leans)."""
        with self.truth.scoring():
            return self.truth.state(self.problem.entities, self.scene)

    def reached(self, domain: Domain) -> bool:
        """The true state satisfies the problem's own (PDDL) goal."""
        truth = self.state()
        return truth is not None and domain.is_goal(self.problem, truth)

    def disturbed(self, move: Move, before: State | None) -> bool:
        """After ``move``, a block other than the moved one has another true support than
        ``before`` (False when either state is unreadable)."""
        after = self.state()
        if before is None or after is None:
            return False
        entities = self.problem.entities
        return any(x != move.entity and before[i] != after[i] for i, x in enumerate(entities))
