"""task.symbolic: the crisp side of planning, apart from the differentiable core.

- ``pddl_io/``: PDDL text in and out (read files, parse domains and problems, check STRIPS,
  read and write plans; one-line errors), its ``__init__`` the API;
- ``strips``: grounded STRIPS semantics (applicable / apply) of a parsed PDDL domain;
- ``ground``: grounding by relaxed reachability (the ground actions the relaxation reaches);
- ``strips_task``: one grounded problem as padded index arrays;
- ``relaxed``: delete relaxations over those arrays (h_max, LM-cut, h_FF);
- ``validate``: a plan checked step by step against the PDDL (the official check);
- ``search``: optimal plans by breadth-first search and A* (for optimal lengths);
- ``lazy_search``: the planner's complete fallback: A* with lazily checked moves, and a lazy
  greedy best-first search on an estimate with helpful actions (the generic lift's);
- ``shorten``: plans with cycles and redundant moves taken out (greedy action elimination);
- ``generate``: seeded random blocksworld problems;
- ``signature``: what recognises a parsed PDDL domain;
- ``proofs/``: proofs that a problem has no plan (relaxed reachability, h^2, invariants,
  exhaustive search), told apart from a planner out of budget.

Nothing here imports torch or a domain (`task.domains` builds on this side, never the other
way round; tests/test_layout.py keeps it so). Reading a PDDL problem into a domain's
`Problem` needs the domain registry, so it lives above both: `task.instances`.
"""
