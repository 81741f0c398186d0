"""Physical lift test (Bullet): does the closed grasp hold the object when the hand lifts it?

The object becomes a dynamic body (mass from its mesh at ``density``), the palm a kinematic
body, the phalanges hinged bodies squeezed as the Barrett hand does: one torque-limited motor per
finger on its proximal joint, the distal coupled to it, breakaway when the proximal is stopped by
the object (the distal closes on alone), worm drives that do not open under load, no travel
limit (see cpp/bayesgrasp/physics/lift_test.hpp). The motors' torque limits are the hand file's
(``torque_nm`` per phalanx, the hand's published strength; ``finger_torque=`` overrides them).
``run(..., trace_every=k)`` records a per-step trace (:mod:`bayesgrasp.lift_trace`). Script:
squeeze 0.15 s, lift 10 cm in 0.4 s, gentle 3-axis shake (1 cm, 3 Hz, 0.5 s), hold 0.1 s, at a
fixed 1/480 s step (deterministic). Success ("lifted") when the object came up with the hand -
its centre of mass rose at least 10 cm - 2 cm - and stayed in it through the shake and the hold
(moved less than 2 cm in the palm frame from the end of the lift)::

    r = lift_test("python/bayesgrasp/data/hands/barrett_bh8.json", hand_pose, joints, V, F)
    r.lifted, r.displacement                    # a LiftResult

``LiftTester`` keeps the object's preprocessing for many tests (``run``, ``run_batch``: a
``LiftBatch`` whose fields are (N,) arrays).

Concave objects (a mug, a pitcher) need a concave collision shape when the hand reaches into
a concavity (the opening, the handle's hole). ``shape="auto"`` (default) then uses an
approximate convex decomposition of the mesh - a compound of a few dozen convex hulls,
computed once per mesh by CoACD (:mod:`bayesgrasp.decomposition`, cached as ``.npz``) - instead
of one tetrahedron per triangle (``shape="tetrahedra"``, far slower; see BENCHMARKS.md).
"""
from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import List, Sequence

from bayesgrasp._args import c_int
import numpy as np

from bayesgrasp import _core
from bayesgrasp.decomposition import convex_decomposition, decomposition_cache_dir
from bayesgrasp.sim import set_fields

__all__ = ["LiftBatch", "LiftOptions", "LiftResult", "LiftTester", "convex_decomposition",
           "decomposition_cache_dir", "is_concave", "lift_test", "lift_test_batch", "make_options"]

LiftOptions = _core.physics.LiftOptions
LiftResult = _core.physics.LiftResult
LiftBatch = _core.physics.LiftBatch


def make_options(**kwargs) -> LiftOptions:
    """LiftOptions from keyword arguments (names as the LiftOptions attributes)."""
    return set_fields(LiftOptions(), kwargs, "lift-test")


def _hand(hand):
    """The hand for the C++ tester: a hand file's path as it is; a Hand, a built-in name or a
    URDF (converted with its sidecar) as the loaded model."""
    from .hand import Hand

    if hand is None:
        from . import DEFAULT_HAND
        from .hand import resolve_hand
        return str(resolve_hand(DEFAULT_HAND))
    if isinstance(hand, Hand):
        return hand.core
    if isinstance(hand, (str, os.PathLike)) and (Path(hand).suffix.lower() == ".urdf" or not Path(hand).exists()):
        return Hand.load(hand).core
    return hand


def is_concave(vertices, faces, hand=None) -> bool:
    """Whether the lift test counts the object as concave (its convex hull's volume more than
    5% above its own): then ``shape="auto"`` needs a convex decomposition."""
    o = make_options(shape="hull")  # cheap: no tetrahedra, no pieces
    return _core.physics.LiftTester(_hand(hand), np.asarray(vertices, dtype=float), np.asarray(faces), o).concave


class LiftTester:
    """Lift tests of one object (V, F in the world frame) with one hand.

    A concave object's convex decomposition is made when the first grasp needs it, not before:
    under ``shape="auto"`` a grasp whose hand stays outside the object's hull is tested on the
    hull, so a can grasped around its side never waits for CoACD (the verdicts are those of the
    tester with the pieces given up front: the same shape for every grasp).

    Args:
        hand: path to a hand JSON file (None: the default hand, bayesgrasp.DEFAULT_HAND) or a HandModel.
        vertices: (N, 3) object vertices (m). faces: (M, 3) int triangles.
        convex_pieces: the object's convex decomposition for shapes ``auto`` (concave objects)
            and ``decomposition``: a list of (K, 3) point arrays in the world frame, a callable
            returning that list when first needed, or None to compute it with
            :func:`convex_decomposition` (cached) when first needed.
        mass_properties: None (the closed mesh's at ``density``) or a core MassProperties in the
            world frame (an open scan's or a weighed object's: ObjectModel.mass_properties_core,
            placed).
        **options: LiftOptions fields (mu, density, table, shape, time_step, ...).
    """

    def __init__(self, hand, vertices, faces, convex_pieces=None, mass_properties=None, **options):
        V, F = np.asarray(vertices, dtype=float), np.asarray(faces)
        o = make_options(**options)
        pending = None
        if callable(convex_pieces):
            pending, convex_pieces = convex_pieces, None
        elif convex_pieces is None:
            pending = lambda: convex_decomposition(V, F)  # noqa: E731
        elif isinstance(convex_pieces, (str, bytes, np.ndarray)) or not isinstance(convex_pieces, Sequence):
            raise ValueError("convex_pieces: expected None, a callable or a list of (K, 3) arrays")
        if o.shape not in ("auto", "decomposition"):
            pending = None
        elif pending is not None and o.shape == "decomposition":
            convex_pieces, pending = pending(), None
        self._make = lambda pieces: _core.physics.LiftTester(_hand(hand), V, F, o, pieces, mass_properties)  # noqa: E731
        # While the decomposition waits, the whole hull stands in as its one piece: it decides the
        # shape per grasp as the real pieces would (the hull unless a link reaches into it), and a
        # grasp that does not stay outside triggers the decomposition before it is simulated.
        # (A convex object never uses pieces: the stand-in is then simply unused.)
        self._t = self._make([V] if pending is not None else convex_pieces)
        self._pending = pending if pending is not None and self._t.concave else None
        self._lock = threading.Lock()

    def _decompose(self) -> None:
        """Makes the postponed decomposition and the tester that uses it (once; if it fails, it
        is tried again next time rather than the stand-in used)."""
        with self._lock:
            if self._pending is not None:
                self._t = self._make(self._pending())
                self._pending = None

    def _ready_for(self, hand_poses: np.ndarray, joints: np.ndarray) -> None:
        """Decomposes first if one of these grasps needs the concave shape. Bad input is left to
        the test itself, whose errors name the arguments as given."""
        if self._pending is None:
            return
        try:
            shapes = self._t.shapes(hand_poses, joints)
        except ValueError:
            return
        if any(s != "hull" for s in shapes):
            self._decompose()

    @property
    def concave(self) -> bool:
        """The object's hull volume is more than 5% above its volume."""
        return self._t.concave

    @property
    def num_pieces(self) -> int:
        """Convex pieces of the decomposition in use (0: none; asking makes a postponed one)."""
        self._decompose()
        return self._t.num_pieces

    @property
    def mass(self) -> float:
        return self._t.mass

    @property
    def com(self) -> np.ndarray:
        """(3,) the object's centre of mass in the world, m."""
        return np.asarray(self._t.com)

    @property
    def shape(self) -> str:
        """Shape prepared: 'hull', 'tetrahedra' or 'decomposition' (auto on a concave object
        still uses the hull for grasps that stay outside it; see the results' ``shape``; asking
        makes a postponed decomposition)."""
        self._decompose()
        return self._t.shape

    def shapes(self, hand_poses, joints) -> List[str]:
        """The shape each grasp's test would use, without simulating: 'hull', or where the hand
        reaches into the hull the concave shape ('decomposition' also while it is postponed)."""
        return self._t.shapes(np.asarray(hand_poses, dtype=float), np.asarray(joints, dtype=float))

    def run(self, hand_pose, joints, trace_every: int = 0) -> LiftResult:
        """One lift test (lifted, displacement, hold_displacement, rotation, squeeze_displacement, height_gain,
        finite, steps, tetrahedra, shape, breakaway). ``trace_every`` > 0: ``result.trace`` records
        every that many steps (see :class:`bayesgrasp.lift_trace.LiftTrace`); 0: None."""
        T, q = np.asarray(hand_pose, dtype=float), np.asarray(joints, dtype=float)
        trace_every = c_int(trace_every, "trace_every")
        if T.shape == (4, 4) and q.ndim == 1:
            self._ready_for(T[None], q[None])
        return self._t.run(T, q, trace_every)

    def run_batch(self, hand_poses, joints, threads=1) -> LiftBatch:
        """N lift tests ((N, 4, 4) poses, (N, J) joints) in C++ threads (0 = all cores): the
        LiftResult fields as (N,) arrays, ``shape`` the list of shapes used."""
        P, J = np.asarray(hand_poses, dtype=float), np.asarray(joints, dtype=float)
        threads = c_int(threads, "threads")
        self._ready_for(P, J)
        return self._t.run_batch(P, J, threads)


def lift_test(hand, hand_pose, joints, vertices, faces, **options) -> LiftResult:
    """One lift test of a closed grasp.

    Args:
        hand: path to a hand JSON file (None: the default hand, bayesgrasp.DEFAULT_HAND) or a HandModel.
        hand_pose: (4, 4) world pose of the hand.
        joints: (J,) closed joint angles (rad), e.g. from the grasp simulator.
        vertices, faces: the object mesh in the world frame.
        **options: LiftOptions fields, e.g. ``mu=0.5, density=1000.0, table=True``.

    Returns:
        a LiftResult: ``lifted`` (bool), ``displacement`` (m), ``hold_displacement`` (m), ``rotation`` (rad),
        ``squeeze_displacement`` (m), ``height_gain`` (m), ``finite``, ``steps``, ``shape``.
    """
    return LiftTester(hand, vertices, faces, **options).run(hand_pose, joints)


def lift_test_batch(hand, hand_poses, joints, vertices, faces, threads=1, **options) -> LiftBatch:
    """N lift tests of one object, in ``threads`` C++ threads; a LiftBatch of (N,) arrays."""
    return LiftTester(hand, vertices, faces, **options).run_batch(hand_poses, joints, threads)
