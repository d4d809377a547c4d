"""tamp.loop: the closed loop observe -> perceive -> plan -> execute -> check -> recover/replan.

- ``episode``: `Episode`, one problem in one simulator, and `run_episode`;
- ``report``: `LoopConfig`, `EpisodeStatus` and `EpisodeReport`;
- ``observe``: what the robot senses (block poses with noise, or the camera);
- ``execute``: one move as a pick-and-place, with its robot-side checks and failure kinds;
- ``recover``: tidying loose blocks, injected nudges, failure descriptions;
- ``faults``: fault injection settings (drop, nudge, noise).
"""
