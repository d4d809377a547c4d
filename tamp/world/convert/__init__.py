"""Scenes made from the other world models: `from_problem` (a Blocksworld PDDL problem laid out
on a named workcell, as the loop lays it out) and `workcells` (the named workcells of
`tamp.obstacles` written as the shipped scene files)."""
