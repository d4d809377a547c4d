"""task: the differentiable soft-T_P task planner and its crisp symbolic side.

Tensor axis glossary (batch first, always):

    B  batch (problems x restarts)          T  horizon (steps in a planning window)
    N  entities (blocks), padded            K  fixed targets (K=1: the table)
    Y  support targets, N + K               A  action columns, Y + 1 (targets + STAY)
    C H W  image channels, height, width    R  regions of interest (entities in an image)
    J  joints                               D  features

Rooms:

- the differentiable core, at the top: ``problem`` (Problem, Move, Plan, PlanResult),
  ``config`` (PlannerConfig), ``soft`` (soft-logic operators), ``rollout`` (the soft-T_P
  transition over a window), ``optimize`` (Adam on the action logits), ``decode`` (logits ->
  legal moves), ``planner`` (receding windows: ``plan`` / ``plan_batch``), ``beliefs`` (soft
  perceived states as planner inputs), ``errors`` (the one exception family);
- ``task.domains``: one file per planning domain, picked up by a registry;
- ``task.symbolic``: the crisp side: PDDL in and out, STRIPS, validation, search, instance
  generation and loading;
- ``task.data``: the embedded 4-operator blocksworld domain and a 5-block example.

Benchmarks of the planner live in `tamp.bench`. ``import task`` stays light: it pulls in no
simulator and no torch until a submodule that needs it is imported.
"""
