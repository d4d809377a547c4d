"""tamp.loop: the closed loop observe -> perceive -> plan -> execute -> check -> recover/replan.

- ``episode``: `Episode`, one problem in one simulator, as a short loop of public steps
  (``start``, ``step``, ``execute``, ``check``, ``observe``, ``report``) that ``given`` drives
  too, and `run_episode`;
- ``config``: `LoopConfig`, the settings of an episode;
- ``report``: `EpisodeReport`, what an episode returns, with its `EpisodeStatus`
  (`tamp.outcome`: the geometric episode's statuses too);
- ``observe``: what the robot senses: block poses (for the arm) and the symbolic state (for the
  planner), from the mocap oracle or from the camera;
- ``sensors``: the two pose sensors, `MocapPoses` (``observe="state"`` only: the one sensor whose
  reading is ground truth, plus optional noise) and `CameraPoses` (RGB-D pose estimation);
- ``execute``: one move as a pick-and-place, with its robot-side checks and failure kinds;
- ``given``: a plan from any source (4-op PDDL actions or moves) executed open-loop, with a
  task-level verdict, the motion outcome and what physically followed, per step;
- ``score``: `Scorer`, the reader of simulator ground truth in the loop (the goal check and
  each move's `MoveScore`: clean, disturbed, or unreadable, which counts against the plan;
  ``given`` also reads it, to score each step, and under the experimenter's grant for
  ``stop_at_invalid``); an episode locks ``sim.truth`` for the rest;
- ``recover``: tidying loose blocks, injected nudges, failure descriptions;
- ``faults``: fault injection settings (drop, nudge, noise).
"""

from tamp.loop.config import LoopConfig
from tamp.loop.episode import Episode, run_episode
from tamp.loop.recover import describe
from tamp.loop.report import EpisodeReport
from tamp.outcome import EpisodeStatus

__all__ = ["Episode", "EpisodeReport", "EpisodeStatus", "LoopConfig", "describe", "run_episode"]
