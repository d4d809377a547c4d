"""task: the differentiable soft-T_P task planner and its crisp symbolic side.

Tensor axis glossary (batch first, always):

    B  batch (problems x restarts)          T  horizon (steps in a planning window)
    N  entities (rows), padded              K  fixed targets (the table; locations; cells)
    Y  support targets, N + K (relational;  A  action columns, Y + 1 (targets + STAY);
       a domain may choose its own)            a domain may choose its own, STAY last
    C H W  image channels, height, width    R  regions of interest (entities in an image)
    J  joints                               D  features

Rooms:

- the differentiable core, at the top: ``problem`` (Problem, Move, Plan, PlanResult),
  ``config`` (PlannerConfig), ``soft`` (soft-logic operators), ``rollout`` (the soft-T_P
  transition over a window), ``optimize`` (Adam on the action logits), ``decode`` (logits ->
  legal moves), ``planner`` (receding windows: ``plan`` / ``plan_batch``), ``beliefs`` (soft
  perceived states as planner inputs), ``errors`` (the one exception family);
- ``task.domains``: one file per planning domain (Blocksworld, Logistics, Sokoban), picked up
  by a registry, and ``strips``, the generic soft lift of any grounded STRIPS domain;
- ``task.symbolic``: the crisp side: PDDL in and out, STRIPS, validation, search, instance
  generation; it never imports torch or a domain;
- ``instances``: a PDDL problem read into the domain that plans it (through the registry),
  with its parsed PDDL and known lengths;
- ``task.data``: the embedded PDDL domains (4-operator blocksworld, logistics-strips,
  typed-sokoban) and a 5-block example.

Benchmarks of the planner live in `tamp.bench`. ``import task`` stays light: it pulls in no
simulator and no torch until a submodule that needs it is imported.
"""
