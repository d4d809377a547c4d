"""task: the differentiable soft-T_P task planner and its crisp symbolic side.

Tensor axis glossary (batch first, always):

    B  batch (problems x restarts)          T  horizon (steps in a planning window)
    N  entities (blocks), padded            K  fixed targets (K=1: the table)
    Y  support targets, N + K               A  action columns, Y + 1 (targets + STAY)
    C H W  image channels, height, width    R  regions of interest (entities in an image)
    J  joints                               D  features

Public entry points: ``task.planner.plan`` / ``plan_batch``, ``task.config.PlannerConfig``,
``task.symbolic.validate.validate``, ``task.domains.get_domain``; ``task.beliefs`` for planning from
soft (perceived) states. ``import task`` stays light: it pulls in no simulator and no torch until a
submodule that needs it is imported.
"""
