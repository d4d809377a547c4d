"""task.symbolic: the crisp side of planning, apart from the differentiable core.

- ``pddl_io``: PDDL text in and out (parse domains, problems and plans; one-line errors);
- ``strips``: grounded STRIPS semantics (applicable / apply) of a parsed PDDL domain;
- ``validate``: a plan checked step by step against the PDDL (the official check);
- ``search``: optimal plans by breadth-first search and A* (for optimal lengths);
- ``generate``: seeded random blocksworld problems;
- ``instances``: a problem with its parsed PDDL and optimum, from files or the embedded example.

Nothing here imports torch.
"""
