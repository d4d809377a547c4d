"""An image that cannot be read while planning ends that instance's plan, not the benchmark."""

from __future__ import annotations

import torch

from perception.errors import PerceptionError
from tamp.bench.vision.perception import _plan
from task.config import PlannerConfig
from task.symbolic.generate import random_problem


def test_one_unreadable_problem_is_left_out_and_the_rest_are_planned():
    torch.set_num_threads(1)
    problems = [random_problem(3, seed) for seed in range(3)]
    seen = []

    def beliefs(indices, states):
        seen.append(tuple(indices))
        if 1 in indices:
            raise PerceptionError("block(s) b not found in the image")
        return None  # the planner's own encoding of the true state

    config = PlannerConfig(restarts=2, iters=10)
    results = _plan(problems, [0, 1, 2], config, 0, beliefs)
    assert sorted(results) == [0, 2]
    assert all(r.solved for r in results.values())
    assert seen[0] == (0, 1, 2)  # the batch first, then one problem at a time
