"""tamp: the loop observe -> perceive -> plan -> move -> execute -> check, and the CLI.

Today it holds the ``tamp`` command line (`tamp.cli`): planning, validating and benchmarking
PDDL blocksworld problems with the soft-T_P planner of `task`. Simulator backends and the
perception-to-motion loop are upcoming.
"""
