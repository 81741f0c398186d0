"""Measurement and stability models for one grasp family, learnt from simulated grasps (thesis §3.2).

The models take the grasp relative to the object: (x, y, yaw) in the object's frame. Inputs to
the GPs are, for top grasps, (x, y, cos yaw, sin yaw), so that yaw wraps; for side grasps the
approach line's offset and azimuth (:class:`.families.Variant`). Two sparse (FITC) GPs
are fitted on simulated grasps of the object with the hand (:mod:`.build`):

* measurement model P(M|A,O): the hand's phalanx joint angles after closing (one output per
  phalanx joint, shared hyper-parameters), Gaussian with the GP's predictive variance plus noise;
* stability model P(S|A,O): the GP regression of the grasp's outcome - by default whether the lift
  test held the object (0 or 1); with ``ModelSettings.success = "epsilon"`` the epsilon quality
  (0 without force closure) - mapped to a probability through z = (mu - threshold) / sd of the
  latent value (threshold 0.5 for the lift outcome, eps_stable for epsilon) and a logistic
  calibration P(S) = 1 / (1 + exp(-(a z + b))) fitted on the outcomes of held-out simulated
  grasps (the plain probit Phi(z) is overconfident on held-out grasps).
"""
from __future__ import annotations

import numpy as np
from scipy.special import expit

from .. import gp as _gp
from ..belief import relative_planar_pose
from .families import Variant
from .settings import ModelSettings
from .table import ModelTable

#: Logistic close to the probit Phi(z): the calibration when none was fitted.
DEFAULT_CALIBRATION = (1.702, 0.0)


def relative_top_grasps(grasps, object_poses) -> np.ndarray:
    """Top grasps (A, 3) in the world and planar object poses (N, 3) -> (A, N, 3) grasps in each
    object's frame: R(-oyaw) (a_xy - o_xy), wrap(a_yaw - o_yaw) into [-pi, pi)."""
    a = np.atleast_2d(np.asarray(grasps, dtype=float))
    o = np.atleast_2d(np.asarray(object_poses, dtype=float))
    return relative_planar_pose(a, o).reshape(len(a), len(o), -1)


def features(rel) -> np.ndarray:
    """(..., 3) relative top grasps -> (..., 4) GP inputs (x, y, cos yaw, sin yaw)."""
    return Variant("top").features(rel)


def _mean_var(model: _gp.SparseGP, X: np.ndarray, include_noise: bool):
    """Predictive mean and variance (N, P) in the outputs' units, with or without the noise."""
    mv = [m.predict(np.ascontiguousarray(X), include_noise) for m in model.models_]
    return np.concatenate([a for a, _ in mv], axis=1), np.concatenate([b for _, b in mv], axis=1)


class GraspModels:
    """The two fitted GPs of one object and hand, with the planners' queries."""

    def __init__(self, measurement: _gp.SparseGP, stability: _gp.SparseGP, settings: ModelSettings,
                 joint_index: np.ndarray, info: dict):
        self.measurement, self.stability, self.settings = measurement, stability, settings
        self.joint_index = np.asarray(joint_index, dtype=int)  # which hand joints are measured
        self.info = info
        self.loaded_from_cache = False  # set by the model builder
        self._tables: dict = {}

    @property
    def family(self) -> str:
        return self.settings.family

    @property
    def variant(self) -> Variant:
        """The family and the hand settings of every grasp these models describe."""
        v = dict(self.info.get("variant") or {"family": self.family, "spread": self.spread})
        return Variant(**v)

    def _features(self, rel: np.ndarray) -> np.ndarray:
        return self.variant.features(rel).reshape(-1, self.variant.n_features)

    def predict_measurement(self, rel):
        """Mean and variance (incl. noise) of the joint angles at relative grasps (..., 3)."""
        rel = np.asarray(rel, dtype=float)
        mean, var = _mean_var(self.measurement, self._features(rel), include_noise=True)
        shape = rel.shape[:-1] + (len(self.joint_index),)
        return mean.reshape(shape), var.reshape(shape)

    def log_likelihood(self, rel, measurement) -> np.ndarray:
        """log P(M = measurement | A, O) at relative grasps (..., 3): a sum over joints."""
        rel = np.asarray(rel, dtype=float)
        m = np.asarray(measurement, dtype=float)
        X = self._features(rel)
        Y = np.broadcast_to(m, (len(X), m.shape[-1]))
        return self.measurement.log_predictive_density(X, Y).reshape(rel.shape[:-1])

    def stability_z(self, rel) -> np.ndarray:
        """z = (mu - threshold) / sd of the stability GP's latent value at relative grasps (..., 3).
        The observation noise is left out: it is mostly the simulator's discontinuity, not
        uncertainty about the grasp."""
        rel = np.asarray(rel, dtype=float)
        mean, var = _mean_var(self.stability, self._features(rel), include_noise=False)
        z = (mean[:, 0] - self.settings.stability_threshold) / np.sqrt(np.maximum(var[:, 0], 1e-12))
        return z.reshape(rel.shape[:-1])

    def _calibration(self):
        return self.info.get("calibration", DEFAULT_CALIBRATION)

    def stability_probability(self, rel) -> np.ndarray:
        """P(S | A, O) at relative grasps (..., 3): the calibrated logistic of z."""
        a, b = self._calibration()
        return expit(a * self.stability_z(rel) + b)

    def log_stability_probability(self, rel) -> np.ndarray:
        a, b = self._calibration()
        return -np.logaddexp(0.0, -(a * self.stability_z(rel) + b))

    @property
    def spread(self) -> float:
        """The finger spread (rad) of every grasp these models describe."""
        return float(self.info.get("spread", self.settings.spread if self.settings.spread is not None else np.pi / 2))

    def grasp_box(self) -> np.ndarray:
        """(2, 2): the x, y box the training grasps were sampled in (lows, highs)."""
        if "grasp_box" in self.info:
            return np.asarray(self.info["grasp_box"], dtype=float)
        r = self.settings.xy_range
        return np.array([[-r, -r], [r, r]])

    @property
    def n_joints(self) -> int:
        return len(self.joint_index)

    def table(self, xy_step: float = 0.002, yaw_step: float = np.radians(5.0)) -> ModelTable:
        """The models tabulated over relative grasps for the planners (built on first use, kept).

        Channel 0 is P(S | A, O), channels 1..K the measurement mean of the K joints and K+1..2K its
        variance (with noise). The grid spans the training box (:meth:`grasp_box`) and all
        yaws; outside the box P(S) is 0 (the models know nothing there, and a GP's prior would
        claim stability) and the measurement channels take the nearest edge value.
        """
        key = (float(xy_step), float(yaw_step))
        if key not in self._tables:
            self._tables[key] = ModelTable.build(self, xy_step, yaw_step)
        return self._tables[key]
