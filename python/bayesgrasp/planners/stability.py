"""Stability maximisation (thesis §3.2, Pub. II, Eq. 3.1): the grasp that maximises the
expected stability sum_j w_j P(S | A, O_j) over the particle belief, found by PSO (in every grasp
family the planner has models for)."""
from __future__ import annotations

from .base import Planner
from .pose_results import Plan


class StabilityPlanner(Planner):
    """Always executes the maximally stable grasp under the current belief."""

    method = "stability"

    def _plan(self) -> Plan:
        b = self.belief
        f, a, v, n = self.most_stable(b.particles, b.weights)
        return Plan(action=a, kind="stability", predicted_stability=v, objective=v, evaluations=n, family=f)
