"""motion: inverse kinematics, jerk-limited joint trajectories and pick-and-place primitives.

Public entry points:

    motion.ik.IKSolver(spec, IKConfig)      batched pytorch_kinematics IK ``solve`` and ``fk``
    motion.ik.top_down_pose / grasp_yaw     top-down TCP targets; the cube's 4-fold yaw symmetry
    motion.ik.ik_refine                     one differentiable Gauss-Newton step: d q / d target
    motion.trajectory.straight_segment      rest-to-rest, exactly straight joint segment (ruckig)
    motion.trajectory.JointTrajectory       sampled times, positions, velocities, accelerations
    motion.pick_place.plan_pick_place       a block move as eight phases of joint trajectories
    motion.errors.MotionError               misuse (wrong shapes); non-convergence is a value

Axis letters follow ``task``'s glossary: ``B`` batch, ``J`` joints (7), ``S`` samples in time.
``import motion`` stays light: torch, pytorch_kinematics and ruckig load only with the submodule
that needs them.
"""
