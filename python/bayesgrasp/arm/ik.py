"""Inverse kinematics for a batch of palm poses: damped least squares, vectorised with numpy.

Each of the B problems (a palm pose and a starting joint vector) iterates

    e  = (p* - p ;  log(R* R^T))                        (the palm's pose error, table frame)
    dq = J^T (J J^T + lambda^2 I)^-1 e                  (damped least squares; Wampler 1986,
                                                         Nakamura & Hanafusa 1986)
    q  <- clip(q + s dq, lower, upper),  s = min(1, max_step / max|dq|)

with J the palm's spatial Jacobian (:meth:`Arm.palm_jacobian`), until |p* - p| <= tol_position
and |log(R* R^T)| <= tol_rotation, or ``iterations`` steps. All problems advance together (one
batched Jacobian and one batched 6x6 solve per step); a problem that has converged stops moving,
and so does one whose error has not fallen by a tenth over the last ``STALL_WINDOW`` steps (a
target out of reach, or a start caught at a limit: the next start is tried instead).
With ``position_only`` only the first three rows are used (an arm of fewer than six joints).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["IKSolution", "solve_ik", "pose_error", "rotation_log"]

STALL_WINDOW = 15


@dataclass
class IKSolution:
    """Result of :func:`solve_ik` for B problems."""

    q: np.ndarray                # (B, dof) joint values, within the limits (unless limits=False)
    position_error: np.ndarray   # (B,) m, |p* - p| at q
    rotation_error: np.ndarray   # (B,) rad, angle of R* R^T at q (0 with position_only)
    converged: np.ndarray        # (B,) bool: both errors within tolerance
    iterations: int              # steps taken by the slowest problem


def rotation_log(R: np.ndarray) -> np.ndarray:
    """(B, 3) rotation vectors of rotations R (B, 3, 3): theta u with cos(theta) = (tr R - 1) / 2 and
    u sin(theta) = vee(R - R^T) / 2; a series near 0, scipy near pi (where vee(R - R^T) vanishes)."""
    v = 0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    c = np.clip(0.5 * (R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2] - 1.0), -1.0, 1.0)
    th = np.arccos(c)
    s = np.sin(th)
    small = th < 1e-4
    f = np.where(small, 1.0 + th * th / 6.0, th / np.where(small, 1.0, s))
    out = f[:, None] * v
    near_pi = th > np.pi - 1e-3
    if near_pi.any():
        out[near_pi] = Rotation.from_matrix(R[near_pi]).as_rotvec()
    return out


def pose_error(R_t: np.ndarray, p_t: np.ndarray, R: np.ndarray, p: np.ndarray,
               position_only: bool = False) -> np.ndarray:
    """(B, 6) the error (p* - p ; log(R* R^T)) of palm poses (R, p) against targets (R_t, p_t)."""
    e = np.zeros((p.shape[0], 6))
    e[:, :3] = p_t - p
    if not position_only:
        e[:, 3:] = rotation_log(R_t @ R.transpose(0, 2, 1))
    return e


def solve_ik(arm, target: np.ndarray, q0: np.ndarray, *, iterations: int, damping: float, max_step: float,
             tol_position: float, tol_rotation: float, position_only: bool = False,
             limits=True) -> IKSolution:
    """Damped least squares from q0 (B, dof) towards the palm poses ``target`` (B, 4, 4) in the table
    frame. ``limits``: True, False, or (B,) bool per problem; False lets the joints run past their
    limits (to tell "no IK solution" from "joint limits")."""
    q = np.array(q0, dtype=float)
    B = q.shape[0]
    R_t, p_t = target[:, :3, :3], target[:, :3, 3]
    rows = slice(0, 3) if position_only else slice(0, 6)
    held = np.broadcast_to(np.asarray(limits, dtype=bool), (B,))[:, None]
    lo = np.where(held, arm.lower, -np.inf)
    hi = np.where(held, arm.upper, np.inf)
    done = np.zeros(B, dtype=bool)
    err = np.zeros((B, 6))
    size = np.full(B, np.inf)      # the error's size STALL_WINDOW steps ago
    active = np.arange(B)
    it = 0
    lam2 = damping * damping
    diag = np.arange(3 if position_only else 6)
    for it in range(iterations + 1):
        R, p, J = arm.palm_jacobian(q[active], checked=True)
        e = pose_error(R_t[active], p_t[active], R, p, position_only)
        err[active] = e
        e2 = e * e
        ep, er = np.sqrt(e2[:, :3].sum(axis=1)), np.sqrt(e2[:, 3:].sum(axis=1))
        ok = (ep <= tol_position) & (er <= tol_rotation)
        done[active[ok]] = True
        keep = ~ok
        if it and it % STALL_WINDOW == 0:   # no tenth of progress over the window: give up on it
            now = ep + er
            keep &= now < 0.9 * size[active]
            size[active] = now
        elif it == 0:
            size[active] = ep + er
        active, J, e = active[keep], J[keep][:, rows], e[keep][:, rows]
        if active.size == 0 or it == iterations:
            break
        Jt = J.transpose(0, 2, 1)
        A = J @ Jt
        A[:, diag, diag] += lam2
        dq = (Jt @ np.linalg.solve(A, e[..., None]))[..., 0]
        big = np.abs(dq).max(axis=1)
        dq *= np.minimum(1.0, max_step / np.maximum(big, 1e-12))[:, None]
        q[active] = np.clip(q[active] + dq, lo[active], hi[active])
    return IKSolution(q, np.linalg.norm(err[:, :3], axis=1), np.linalg.norm(err[:, 3:], axis=1), done, it)
