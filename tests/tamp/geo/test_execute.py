"""`tamp.geo.execute.run_move` reads the gripper after the release: an object wedged between
the opened fingers is gripped again and let go before the hand retreats with it."""

from __future__ import annotations

import numpy as np
import pytest

from motion.grasps import grasps
from motion.pick_place import Phase
from motion.trajectory import JointTrajectory
from robots.panda import PANDA
from tamp.geo.check import MoveCheck
from tamp.geo.execute import RunConfig, run_move
from tamp.geo.types import GeoMove, Place
from tamp.outcome import Failure
from tamp.sim.base import GripperReading

WIDTH = 0.057  # m, the object between the fingers
# the opening PyBullet read with a cuboid wedged between the open pads (sorting, development
# variant 1, move 6): 6.1 cm, both fingers pushing 33 N
WEDGED = GripperReading(0.0612, 33.5, 33.0)


class _Hand:
    """A simulator reduced to its arm and gripper: the fingers close on the object, and open
    to the stroke except for the first ``stuck`` openings after a grasp, which stay wedged."""

    grasp = "friction"
    dt = 0.002

    def __init__(self, stuck: int, closes: float = WIDTH) -> None:
        self.stuck, self.closes, self.time = stuck, closes, 0.0  # closes: the first closing
        self.commands: list[tuple[str, int]] = []  # (gripper, samples) per run
        self._reading = GripperReading(2 * PANDA.finger_open, 0.0, 0.0)

    def run(self, trajectory, gripper, release_at=None, on_frame=None, expected=None) -> float:
        self.commands.append((gripper, len(trajectory.positions)))
        self.time += trajectory.duration
        if gripper == "closed":
            self._reading = GripperReading(self.closes, 40.0, 40.0)
            self.closes = WIDTH
        elif self._reading.width < 2 * PANDA.finger_open - 1e-9:  # opening on the object
            wedged = self.stuck > 0
            self.stuck -= wedged
            self._reading = WEDGED if wedged else GripperReading(2 * PANDA.finger_open, 0, 0)
        return 0.0

    def gripper(self) -> GripperReading:
        return self._reading

    def arm_q(self) -> np.ndarray:
        return np.asarray(PANDA.q_home)

    def detach(self) -> None:
        pass


def _move() -> tuple[GeoMove, MoveCheck]:
    grasp = next(g for g in grasps("cuboid", (0.0235, WIDTH / 2, 0.0255)) if g.name == "top0")
    q = np.asarray(PANDA.q_home)
    names = ("approach", "descend", "close", "lift", "transit", "lower", "open", "retreat")
    closed = ("close", "lift", "transit", "lower")
    phases = tuple(
        Phase(n, JointTrajectory.hold(q, 0.1 + 0.01 * k), "closed" if n in closed else "open")
        for k, n in enumerate(names)
    )
    move = GeoMove("o6", Place("zone.c1", "zone", (0.28, 0.4, 0.0255)), grasp)
    return move, MoveCheck(True, grasp, motion=phases)


@pytest.mark.parametrize("stuck", [0, 1])
def test_an_object_wedged_between_the_opened_fingers_is_gripped_again_and_let_go(stuck):
    move, check = _move()
    hand = _Hand(stuck)
    ran = run_move(hand, move, check, ("table", "table"), RunConfig())
    assert ran.ok
    retreat = len(check.motion[-1].trajectory.positions)
    assert hand.commands[-1] == ("open", retreat)  # the hand retreats last ...
    assert hand.gripper().width == pytest.approx(2 * PANDA.finger_open)  # ... opened
    after_open = [g for g, _ in hand.commands[7:-1]]  # between the open phase and the retreat
    assert after_open == ["closed", "open"] * stuck
    assert ran.evidence.get("regrasped", 0) == stuck


def test_fingers_that_never_open_are_evidence_of_the_move_after_the_tries():
    move, check = _move()
    hand = _Hand(stuck=50)
    config = RunConfig()
    ran = run_move(hand, move, check, ("table", "table"), config)
    assert ran.evidence["regrasped"] == config.release_tries
    assert ran.evidence["wiggled"] == len(config.wiggles)
    assert ran.evidence["not_released"]["finger_width"] == pytest.approx(WEDGED.width)


def test_an_object_the_regrasps_leave_wedged_is_freed_by_turning_the_wrist():
    """Sorting variant 11 in PyBullet: two re-grasps left the fingers at 5.1 cm pushing 30 N;
    turning the wrist a little each way with the fingers open let the object go."""
    move, check = _move()
    hand = _Hand(stuck=5)  # the open phase and two reopenings, then one turn and back
    config = RunConfig()
    ran = run_move(hand, move, check, ("table", "table"), config)
    assert ran.ok and ran.evidence["regrasped"] == config.release_tries
    assert ran.evidence["wiggled"] == 2 and "not_released" not in ran.evidence
    assert hand.gripper().width == pytest.approx(2 * PANDA.finger_open)
    after_open = [g for g, _ in hand.commands[7:-1]]  # re-grasps, then turns with it open
    assert after_open == ["closed", "open"] * config.release_tries + ["open"] * 4


def test_a_missed_grasp_frees_an_object_wedged_askew_between_the_fingers_before_backing_off():
    move, check = _move()
    hand = _Hand(stuck=1, closes=0.045)  # closed askew: 4.5 cm where the object is 5.7
    ran = run_move(hand, move, check, ("table", "table"), RunConfig())
    assert ran.failure is Failure.GRASP_MISSED
    assert ran.evidence["regrasped"] == 1 and "not_released" not in ran.evidence
    descend = len(check.motion[1].trajectory.positions)
    after_close = hand.commands[3:]  # the back-off: open, close on it again, open, back up
    assert [g for g, _ in after_close] == ["open", "closed", "open", "open"]
    assert after_close[-1] == ("open", descend)  # ... along the descent, last
    assert hand.gripper().width == pytest.approx(2 * PANDA.finger_open)
