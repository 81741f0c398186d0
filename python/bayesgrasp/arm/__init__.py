"""The arm the hand is mounted on: kinematics, batched inverse kinematics and the arm's collisions
with the table and the object, fed by a URDF as the hand is (:mod:`bayesgrasp.hand_urdf`).

    from bayesgrasp.arm import Arm, ReachOptions, check_reach, default_mount
    arm = Arm.load("kuka_lbr4", base=(-0.7, 0.0, 0.0, 0.0), mount=default_mount(hand))
    result = check_reach(arm, palm_poses, object_mesh=mesh, options=ReachOptions(seeds=8))

Files by step: :mod:`.model` (the URDF, the chain, forward kinematics and the Jacobian),
:mod:`.mount` (the hand on the flange), :mod:`.ik` (damped least squares, batched),
:mod:`.collision` (links against table and object), :mod:`.reach` (the check, its options and result).
"""
from .model import DEFAULT_BASE, ROBOTS_DIR, Arm, base_pose, builtin_arms, resolve_arm
from .mount import default_mount, mount_pose, palm_depth
from .reach import REASONS, ReachOptions, ReachResult, arm_record, check_reach

__all__ = ["Arm", "DEFAULT_BASE", "ROBOTS_DIR", "REASONS", "ReachOptions", "ReachResult", "base_pose", "builtin_arms",
           "arm_record", "check_reach", "default_mount", "mount_pose", "palm_depth", "resolve_arm"]
