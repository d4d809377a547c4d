"""tamp.loop: the closed loop observe -> perceive -> plan -> execute -> check -> recover/replan.

- ``episode``: `Episode`, one problem in one simulator, as a short loop of named steps, and
  `run_episode`;
- ``config``: `LoopConfig`, the settings of an episode;
- ``report``: `EpisodeStatus` and `EpisodeReport`, what an episode returns;
- ``observe``: what the robot senses (block poses with noise, or the camera);
- ``execute``: one move as a pick-and-place, with its robot-side checks and failure kinds;
- ``recover``: tidying loose blocks, injected nudges, failure descriptions;
- ``faults``: fault injection settings (drop, nudge, noise).
"""

from tamp.loop.config import LoopConfig
from tamp.loop.episode import Episode, run_episode
from tamp.loop.recover import describe
from tamp.loop.report import EpisodeReport, EpisodeStatus

__all__ = ["Episode", "EpisodeReport", "EpisodeStatus", "LoopConfig", "describe", "run_episode"]
