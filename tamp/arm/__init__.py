"""The arm's side of motion-aware task planning: what the planner knows of the arm and what it
costs to move each block (`costs.ArmCosts`, a `task.costs.CostSource`), with its supporting
pieces: the arm as the planner knows it (`arm.Arm`), the memory of the moves it failed
(`failures`), the block poses predicted in a planned state (`predict`) and the IK of each pick
and place point, solved once per source (`sites`).
"""
