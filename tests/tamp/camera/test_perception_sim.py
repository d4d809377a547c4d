"""Perception on simulator renders: the shipped checkpoint, hidden blocks, a camera episode.

Uses the checkpoint shipped in ``perception/support.pt``; each test takes seconds.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

from perception import CHECKPOINT
from perception import data as pdata
from perception.errors import PerceptionError
from perception.perceive import Perceiver
from perception.train import evaluate, load_checkpoint
from tamp.camera.dataset import generate
from tamp.camera.from_images import perceived_goal, perceived_state
from tamp.camera.render import StateRenderer
from tamp.camera.states import complete_goal
from tamp.loop import EpisodeStatus, LoopConfig, run_episode
from tamp.scene import Pose
from tamp.sim import SIMULATORS
from task.problem import TABLE, Problem
from task.symbolic.generate import block_names, random_towers

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def perceiver() -> Perceiver:
    return Perceiver.load(CHECKPOINT)


def test_the_shipped_checkpoint_says_how_it_was_made():
    _, meta = load_checkpoint(CHECKPOINT)
    assert meta["command"].startswith("tamp perception train")
    assert "seed" in meta and meta["train"]["data_seed"] != meta["test"]["data_seed"]
    assert meta["test"]["scenes"] > 0 and "relation_accuracy" in meta["test"]


@pytest.mark.parametrize("sim", SIMULATORS)
def test_the_shipped_checkpoint_is_accurate_on_fresh_scenes(sim):
    model, meta = load_checkpoint(CHECKPOINT)
    seed = 7  # neither the training nor the test data seed of the checkpoint
    assert seed not in (meta["train"]["data_seed"], meta["test"]["data_seed"])
    fresh = pdata.tensors(generate(8, seed, (sim,)))
    scores = evaluate(model, fresh)
    assert scores["scenes"] == 8 and scores["unreadable"] == 0 and scores["blocks"] >= 3 * 8
    # Recomputed, not read from the checkpoint (which claims ~0.998 on its test set): 1.0 on
    # every block and scene of seeds 11-15 in both simulators. The floors allow a few misreads.
    assert scores["relation_accuracy"] >= 0.9 and scores["scene_accuracy"] >= 0.75


@pytest.mark.parametrize("sim", SIMULATORS)
def test_the_shipped_checkpoint_reads_fresh_renders(sim, perceiver):
    with StateRenderer(sim) as renderer:
        for k in range(4):
            names = block_names(3 + k)
            state = random_towers(names, random.Random(100 + k))
            problem = Problem("p", "blocksworld", names, state, ())
            image = renderer.render(names, state, seed=1000 + k)
            read, F = perceived_state(problem, perceiver, image)
            assert read == state
            assert F.shape == (len(names), len(names) + 1)
            np.testing.assert_allclose(F.sum(-1).numpy(), 1.0, rtol=1e-5)


def test_a_block_out_of_view_is_named(perceiver):
    names = ("a", "b", "c")
    problem = Problem("p", "blocksworld", names, (TABLE, "a", TABLE), ())
    with StateRenderer("pybullet") as renderer:
        renderer.render(names, problem.init, seed=0)
        renderer.sim.set_block_pose(renderer.names[2], Pose((3.0, 3.0, 0.025)))  # c, far away
        image = renderer.sim.render()
    with pytest.raises(PerceptionError, match=r"block\(s\) c not found"):
        perceived_state(problem, perceiver, image)


def test_the_perceived_goal_is_the_completed_goal_scene(perceiver):
    problem = Problem(
        "p", "blocksworld", ("a", "b", "c", "d"), (TABLE, "a", TABLE, "c"), (("a", "d"),)
    )
    full = complete_goal(problem)
    with StateRenderer("pybullet") as renderer:
        image = renderer.render(problem.entities, full, seed=3)
    seen = perceived_goal(problem, perceiver, image)
    assert seen.goal == tuple(zip(problem.entities, full, strict=True))


def test_an_image_driven_episode_reaches_its_goal():
    problem = Problem(
        "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
    )
    report = run_episode(problem, LoopConfig(sim="pybullet", observe="camera"), seed=0)
    assert report.status is EpisodeStatus.GOAL_REACHED, report.reason
    assert report.reached_goal  # scored on simulator ground truth
