"""The camera loop reads workcell (cube) renders: a checkpoint trained on LatPlan's scene is
refused in one line before anything is rendered (it used to read the cubes confidently wrong)."""

from __future__ import annotations

import pytest

from perception import CHECKPOINT
from perception.errors import PerceptionError
from tamp.loop import LoopConfig
from tamp.loop.observe import camera_goal
from task.problem import TABLE, Problem

LATPLAN = CHECKPOINT.with_name("support-latplan.pt")
TWO = Problem("two", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))


def test_the_camera_loop_refuses_a_latplan_checkpoint():
    config = LoopConfig(observe="camera", checkpoint=str(LATPLAN))
    with pytest.raises(PerceptionError) as excinfo:
        camera_goal(TWO, config, 0)
    message = str(excinfo.value)
    assert "\n" not in message and str(LATPLAN) in message
    assert "trained on the latplan scene, not cubes" in message
