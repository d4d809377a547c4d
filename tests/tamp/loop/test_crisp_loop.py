"""The loop's crisp protocols: decoded moves are checked against the observed state (the
default, what a robot has) or, as an oracle variant, against simulator ground truth."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from tamp.loop import Episode, EpisodeStatus, LoopConfig
from tamp.scene import SceneConfig, layout
from tamp.sim.truth import GroundTruth
from task.errors import TampError
from task.problem import TABLE, Problem

THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)
MISREAD = (TABLE, TABLE, TABLE)  # b is really on a


def _episode(crisp: str) -> SimpleNamespace:
    """What `Episode._crisp_basis` uses: a locked ground truth of THREE's initial layout."""
    poses = layout(THREE.entities, THREE.init, SceneConfig(), 0)
    truth = GroundTruth(lambda: poses)
    truth.lock()
    config = LoopConfig(crisp=crisp)
    return SimpleNamespace(config=config, sim=SimpleNamespace(truth=truth), problem=THREE)


def test_the_default_plans_from_the_observed_state_and_reads_no_truth():
    episode = _episode(LoopConfig().crisp)
    assert episode.config.crisp == "perceived"
    assert Episode._crisp_basis(episode, MISREAD) == MISREAD
    assert not episode.sim.truth.reads


def test_the_oracle_variant_plans_from_the_true_state_through_the_oracle_grant():
    episode = _episode("true")
    assert Episode._crisp_basis(episode, MISREAD) == THREE.init
    assert episode.sim.truth.purposes() == {"oracle"}


def test_an_unknown_crisp_protocol_is_named():
    with pytest.raises(TampError, match="unknown crisp protocol 'oracle'"):
        LoopConfig(crisp="oracle")


@pytest.mark.sim
def test_a_camera_episode_with_the_oracle_variant_reaches_the_goal():
    episode = Episode(THREE, LoopConfig(observe="camera", crisp="true"), seed=0)
    report = episode.run()
    assert report.status is EpisodeStatus.GOAL_REACHED and report.reached_goal, report.reason
    assert report.first_plan and str(report.first_plan[0]) == report.plans[0][0]
    reads = episode.sim.truth.reads
    assert {c for g, c in reads if g == "oracle"} == {"tamp.loop.episode.Episode._crisp_basis"}
