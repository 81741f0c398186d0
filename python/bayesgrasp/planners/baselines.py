"""Baselines the thesis's planners are compared with.

* :class:`MLPosePlanner` plans the maximally stable grasp for one pose only, the belief's most
  probable particle (no marginalisation over the uncertainty), and updates the belief as the
  other planners do.
* :class:`OpenLoopPlanner` plans like the stability planner but never updates its belief: every
  attempt is planned on the initial estimate (only the search's random seed changes).
"""
from __future__ import annotations

import numpy as np

from .base import Planner
from .pose_results import Observation, Plan
from .stability import StabilityPlanner


class MLPosePlanner(Planner):
    method = "ml_pose"

    def _plan(self) -> Plan:
        pose = self.mode()
        f, a, v, n = self.most_stable(pose[None, :], np.ones(1))
        return Plan(action=a, kind="stability", predicted_stability=self.expected_stability(a, f), objective=v,
                    evaluations=n, family=f)


class OpenLoopPlanner(StabilityPlanner):
    method = "open_loop"

    def _update(self, obs: Observation) -> None:
        """No belief update: the measurement is recorded and ignored."""
