"""Which of a planner's actions an arm can reach: the ``reach`` of a :class:`~.base.Planner`.

An action (x, y, yaw) of a grasp family becomes a palm pose the way it is executed: the family's
grasp (:meth:`bayesgrasp.models.families.Variant.simulate`: the hand descends or moves along its
approach to the first contact) in a world holding the object at the pose the planner believes
(the belief's mean); those palm poses go to one batched :func:`bayesgrasp.arm.check_reach` with the
object's mesh at that pose.

    planner.reach = ActionReach(arm, "mug", hand="barrett_bh8")
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from ..arm import Arm, ReachOptions, check_reach
from ..belief import relative_planar_pose
from ..world import World

__all__ = ["ActionReach"]


class ActionReach:
    """(models, actions (K, 3) world, object pose (3,)) -> (K,) bool: the arm reaches the grasp.

    ``obj``: the object (name, path or ObjectModel); ``hand``: the hand the grasps are made with;
    ``options``: the reach check's (:class:`~bayesgrasp.arm.ReachOptions`). The world at a pose is
    kept for the next call at the same pose (a planner asks many times per plan)."""

    def __init__(self, arm: Arm, obj, hand, options: Optional[ReachOptions] = None):
        if not isinstance(arm, Arm):
            raise ValueError(f"arm: expected a bayesgrasp.arm.Arm, got {type(arm).__name__}")
        self.arm, self.obj, self.hand = arm, obj, hand
        self.options = options or ReachOptions()
        self._world, self._pose = None, None
        self.calls = 0

    def world(self, pose) -> World:
        pose = np.asarray(pose, dtype=float).ravel()
        if self._world is None or not np.array_equal(pose, self._pose):
            self._world, self._pose = World.single(self.obj, pose=pose.tolist(), hand=self.hand), pose.copy()
        return self._world

    def palm_poses(self, models, actions, pose) -> np.ndarray:
        """(K, 4, 4) the palm poses in the world where ``models``' family closes for the actions,
        with the object at ``pose``."""
        world = self.world(pose)
        rel = relative_planar_pose(np.atleast_2d(np.asarray(actions, dtype=float)), np.asarray(pose, dtype=float)[None])
        batch = models.variant.simulate(world, rel, lift=False, threads=1, quality=False)
        return np.asarray(batch.hand_pose)

    def __call__(self, models, actions, pose) -> np.ndarray:
        self.calls += 1
        world = self.world(pose)
        result = check_reach(self.arm, self.palm_poses(models, actions, pose), (world.vertices, world.faces),
                             self.options)
        return result.reachable
