"""Physical lift test (Bullet): does the closed grasp hold the object when the hand lifts it?

The object becomes a dynamic body (mass from its mesh at ``density``), the palm a kinematic
body, the phalanges motor-driven hinged bodies that keep squeezing (bounded torque, not
backdrivable). Script: squeeze 0.15 s, lift 10 cm in 0.4 s, gentle 3-axis shake (1 cm,
3 Hz, 0.5 s), hold 0.1 s, at a fixed 1/720 s step (deterministic). Success when the object's
centre of mass moved less than 2 cm relative to the palm (after the squeeze)::

    r = lift_test("python/bayesgrasp/data/hands/barrett_bh8.json", hand_pose, joints, V, F)
    r["lifted"], r["displacement"]

``LiftTester`` keeps the object's preprocessing for many tests (``run``, ``run_batch``).
"""
from __future__ import annotations

import os

import numpy as np

from bayesgrasp import _core

__all__ = ["BARRETT_HAND", "LiftOptions", "LiftTester", "lift_test", "lift_test_batch", "make_options"]

#: Path of the built-in Barrett BH8 hand file.
BARRETT_HAND = os.path.join(os.path.dirname(__file__), "data", "hands", "barrett_bh8.json")

LiftOptions = _core.physics.LiftOptions


def make_options(**kwargs) -> LiftOptions:
    """LiftOptions from keyword arguments (names as the LiftOptions attributes)."""
    o = LiftOptions()
    for k, v in kwargs.items():
        if k.startswith("_") or not hasattr(o, k):
            raise ValueError(f"{k}: not a lift-test option")
        setattr(o, k, v)
    return o


def _hand(hand):
    return BARRETT_HAND if hand is None else hand


class LiftTester:
    """Lift tests of one object (V, F in the world frame) with one hand.

    Args:
        hand: path to a hand JSON file (None: the built-in Barrett hand) or a HandModel.
        vertices: (N, 3) object vertices (m). faces: (M, 3) int triangles.
        **options: LiftOptions fields (mu, density, table, shape, time_step, ...).
    """

    def __init__(self, hand, vertices, faces, **options):
        self._t = _core.physics.LiftTester(_hand(hand), np.asarray(vertices, dtype=float),
                                           np.asarray(faces), make_options(**options))

    @property
    def mass(self) -> float:
        return self._t.mass

    @property
    def shape(self) -> str:
        return self._t.shape

    def run(self, hand_pose, joints) -> dict:
        """One lift test; returns a dict (lifted, displacement, rotation, squeeze_displacement,
        height_gain, finite, steps)."""
        return self._t.run(np.asarray(hand_pose, dtype=float), np.asarray(joints, dtype=float))

    def run_batch(self, hand_poses, joints, threads=1) -> dict:
        """N lift tests ((N, 4, 4) poses, (N, J) joints) in C++ threads; dict of (N,) arrays."""
        return self._t.run_batch(np.asarray(hand_poses, dtype=float), np.asarray(joints, dtype=float),
                                 int(threads))


def lift_test(hand, hand_pose, joints, vertices, faces, **options) -> dict:
    """One lift test of a closed grasp.

    Args:
        hand: path to a hand JSON file (None: the built-in Barrett hand) or a HandModel.
        hand_pose: (4, 4) world pose of the hand.
        joints: (J,) closed joint angles (rad), e.g. from the grasp simulator.
        vertices, faces: the object mesh in the world frame.
        **options: LiftOptions fields, e.g. ``mu=0.5, density=1000.0, table=True``.

    Returns:
        dict with ``lifted`` (bool), ``displacement`` (m), ``rotation`` (rad),
        ``squeeze_displacement`` (m), ``height_gain`` (m), ``finite``, ``steps``.
    """
    return LiftTester(hand, vertices, faces, **options).run(hand_pose, joints)


def lift_test_batch(hand, hand_poses, joints, vertices, faces, threads=1, **options) -> dict:
    """N lift tests of one object, in ``threads`` C++ threads; dict of (N,) arrays."""
    return LiftTester(hand, vertices, faces, **options).run_batch(hand_poses, joints, threads)
