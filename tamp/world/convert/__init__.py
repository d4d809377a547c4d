"""Scenes made from the other world models: `from_problem` (a Blocksworld PDDL problem laid out
on a named workcell, as the loop lays it out), `from_poses` (the loop's observed block poses as
a scene, and the loop's Blocksworld state read from it: `read_state`) and `workcells` (the named
workcells of `tamp.obstacles` written as the shipped scene files)."""
