"""`GeoEpisodeConfig`: the settings of one geometric TAMP episode
(`tamp.geo.episode.run_geo_episode`): which planner, which simulator, the seed, the limits, the
pose sensor, the grasp model, injected faults, a video and a PDDL domain to plan through.

What the caller holds (an IK solver and collision model to reuse, a progress callback) is no
setting: the episode takes it as keyword arguments beside the config. Override a default with
`dataclasses.replace`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tamp.geo.search import SearchConfig
from tamp.geo.types import GeoLimits
from tamp.modes import GeoPlanner, Observation
from task.errors import member


@dataclass(frozen=True)
class GeoEpisodeConfig:
    """Settings of a geometric episode.

    ``planner``: a `tamp.modes.GeoPlanner` or its name (ours by default); ``sim``: ``pybullet``
    or ``mujoco``; ``seed``: the places sampled and each move's check; ``limits``: moves run,
    replans and each planner call's wall clock (`GeoLimits`' documented defaults, those of
    ``tamp run`` and ``tamp bench tamp``); ``search``: the planner's budgets and choices (None:
    `SearchConfig` with ``seed`` and ``limits.planning_s``, see `search_config`);
    ``observation``: the pose sensor, an `tamp.modes.Observation` or its name; ``grasp``:
    ``friction`` (physical) or ``weld`` (attach); fault injection (the loop's, `--inject`):
    ``drops``, the move indices (0-based) on which the gripper opens mid-transit, ``nudges``,
    the move indices after which the object just placed (when the move succeeded) is pushed
    ``nudge_m`` m in a random direction, and ``noise``, the probability per pose reading that
    Gaussian noise of ``noise_sigma`` m is added to every observed position (the directions and
    the noise drawn from ``seed``); ``video``: a file to record the episode
    to (.mp4 or .gif; None: no video); ``domain``: ``(pddl_domain_text, binding_text)`` the
    motion-aware planner plans through (`tamp.geo.ours.plan_pddl`: Tower of Hanoi by its rules;
    refused for the other planners, which plan over the moves the geometry allows)."""

    planner: GeoPlanner = GeoPlanner.MOTION_AWARE
    sim: str = "pybullet"
    seed: int = 0
    limits: GeoLimits = GeoLimits()
    search: SearchConfig | None = None
    observation: Observation = Observation.STATE
    grasp: str = "friction"
    drops: tuple[int, ...] = ()
    nudges: tuple[int, ...] = ()
    nudge_m: float = 0.06
    noise: float = 0.0
    noise_sigma: float = 0.01
    video: str | Path | None = None
    domain: tuple[str, str] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "planner", member(GeoPlanner, self.planner, "planner"))
        object.__setattr__(
            self, "observation", member(Observation, self.observation, "observation")
        )

    def search_config(self) -> SearchConfig:
        """The planner's settings: ``search``, or the default with ``seed`` and the limits'
        planning time."""
        if self.search is not None:
            return self.search
        return SearchConfig(seed=self.seed, max_time_s=self.limits.planning_s)
