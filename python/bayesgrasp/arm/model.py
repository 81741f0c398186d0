"""The arm as data: a serial chain read from a URDF by pinocchio, its flange, the hand's mount and
the arm's base in the table frame.

    arm = Arm.load("kuka_lbr4", base=(-0.6, 0.0, 0.0, 0.0))   # built-in, or a path to any URDF
    T = arm.flange_poses(q)           # (B, 4, 4) flange in the table frame, q (B, dof)
    P = arm.palm_poses(q)             # (B, 4, 4) palm (hand frame) in the table frame

pinocchio parses the URDF (joints, limits, collision shapes as coal geometries); the kinematics
of the chain from the root to the flange are evaluated here with numpy, batched over B joint
vectors, from the joint placements and axes pinocchio read:

    T_j(q) = T_parent(j)(q) * M_j * exp(a_j q_j)          (forward kinematics, one joint at a time)

where M_j is the joint's placement in its parent joint's frame and exp(a q) the rotation by q
about the unit axis a (Rodrigues) or the translation q a. Only the joints on the chain move;
every other joint of the URDF stays at zero (a URDF holding more than the arm is fine).
"""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional, Sequence

import numpy as np

__all__ = ["Arm", "ROBOTS_DIR", "builtin_arms", "base_pose", "resolve_arm"]

ROBOTS_DIR = Path(__file__).resolve().parent.parent / "data" / "robots"
#: X, Y, Z (m), YAW (rad) of the arm's root in the table frame when none is given: 0.6 m behind the
#: table's origin, facing +x (the command line's --robot-base and the service's robot_base)
DEFAULT_BASE = (-0.6, 0.0, 0.0, 0.0)


def builtin_arms() -> List[str]:
    """Names of the shipped arm URDFs (``kuka_lbr4``)."""
    return sorted(p.stem for p in ROBOTS_DIR.glob("*.urdf"))


def resolve_arm(name_or_path) -> Path:
    """An existing URDF path, or a built-in arm's name (with or without ``.urdf``)."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    cand = ROBOTS_DIR / (p.name if p.suffix == ".urdf" else f"{p.name}.urdf")
    if p.parent == Path(".") and cand.is_file():
        return cand
    raise ValueError(f"urdf: no such file and no built-in arm '{name_or_path}' (built-in: {', '.join(builtin_arms())})")


def base_pose(xyzyaw: Sequence[float]) -> np.ndarray:
    """The 4x4 pose of the arm's root in the table frame from X, Y, Z (m) and YAW (rad, about z)."""
    v = np.asarray(xyzyaw, dtype=float).ravel()
    if v.shape != (4,) or not np.all(np.isfinite(v)):
        raise ValueError(f"base: expected X, Y, Z, YAW (m, m, m, rad) or a 4x4 pose, got {xyzyaw!r}")
    c, s = np.cos(v[3]), np.sin(v[3])
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = v[:3]
    return T


def _pose4(T, name: str) -> np.ndarray:
    """A 4x4 rigid transform, checked (finite, rotation orthonormal with det +1, last row 0 0 0 1)."""
    T = np.asarray(T, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ValueError(f"{name}: expected a finite 4x4 pose, got shape {T.shape}")
    R = T[:3, :3]
    if (not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or abs(np.linalg.det(R) - 1) > 1e-6
            or not np.allclose(T[3], [0, 0, 0, 1])):
        raise ValueError(f"{name}: not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)")
    return T.copy()


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


class Arm:
    """A serial arm from a URDF with the hand mounted at its flange.

    ``flange``: the link the hand is mounted on (default: the end of the URDF's chain, the link of
    its last moving joint). ``mount``: 4x4 pose of the palm (the hand frame: origin at the centre of
    the palm face, +z the approach) in the flange's frame (default: identity; see
    :func:`bayesgrasp.arm.mount.default_mount` for a hand's base on the flange). ``base``: the
    URDF root's pose in the table frame, X, Y, Z, YAW or a 4x4 (default: the origin).
    """

    def __init__(self, urdf, flange: Optional[str] = None, mount=None, base=None):
        import pinocchio as pin   # the URDF parser and the collision shapes (coal)

        path = resolve_arm(urdf)
        self.urdf = str(path)
        try:
            model = pin.buildModelFromUrdf(str(path))
            geom = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION,
                                         package_dirs=[str(path.parent)])
        except Exception as e:   # pinocchio's parser raises RuntimeError/ValueError with its own text
            raise ValueError(f"urdf: {path}: pinocchio could not read it ({e})") from e
        self.model = model
        self._collision = geom
        links = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
        if flange is None:
            moving = [f for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == model.njoints - 1]
            if model.njoints < 2 or not moving:
                raise ValueError(f"urdf: {path} has no moving joint")
            flange = moving[-1].name
        elif flange not in links:
            raise ValueError(f"flange: the URDF has no link '{flange}' (links: {', '.join(links)})")
        self.flange = flange
        fid = model.getFrameId(flange, pin.FrameType.BODY)
        frame = model.frames[fid]
        self._flange_in_joint = np.asarray(frame.placement.homogeneous)
        # the chain: the joints from the root to the flange's joint, in the URDF's (pinocchio's) order
        chain, j = [], frame.parentJoint
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        self._chain = chain[::-1]
        if not self._chain:
            raise ValueError(f"flange: link '{flange}' is fixed to the root; no joint moves it")
        self._read_joints(pin)
        self.mount = np.eye(4) if mount is None else mount
        self.set_base(np.zeros(4) if base is None else base)

    @classmethod
    def load(cls, urdf, flange: Optional[str] = None, mount=None, base=None) -> "Arm":
        """An arm from a built-in name (:func:`builtin_arms`) or a URDF path."""
        return cls(urdf, flange=flange, mount=mount, base=base)

    def _read_joints(self, pin) -> None:
        """Placement, axis, type and limits of each chain joint, as pinocchio parsed them. The axis is
        read off the joint's own motion at q = 0.5 (rotation log / translation), which covers
        pinocchio's aligned (RX, RY, RZ, PX...) and unaligned joint models alike."""
        m = self.model
        names, M, axes, prism, lo, hi, parent = [], [], [], [], [], [], []
        index = {j: k for k, j in enumerate(self._chain)}
        for j in self._chain:
            jm = m.joints[j]
            if jm.nv != 1:
                raise ValueError(f"urdf: joint '{m.names[j]}' has {jm.nv} degrees of freedom; the arm takes "
                                 "revolute, continuous and prismatic joints")
            q = pin.neutral(m)
            if jm.nq == 2:   # continuous joint: (cos, sin) of its angle
                q[jm.idx_q:jm.idx_q + 2] = [np.cos(0.5), np.sin(0.5)]
            else:
                q[jm.idx_q] = 0.5
            data = m.createData()
            pin.forwardKinematics(m, data, q)
            motion = m.jointPlacements[j].inverse() * data.liMi[j]   # exp(a * 0.5) in the joint's frame
            w = pin.log3(motion.rotation) / 0.5
            is_prism = np.linalg.norm(w) < 1e-9
            a = motion.translation / 0.5 if is_prism else w
            axes.append(a / np.linalg.norm(a))
            prism.append(bool(is_prism))
            M.append(np.asarray(m.jointPlacements[j].homogeneous))
            names.append(m.names[j])
            if jm.nq == 2:
                lo.append(-np.pi)
                hi.append(np.pi)
            else:
                lo.append(float(m.lowerPositionLimit[jm.idx_q]))
                hi.append(float(m.upperPositionLimit[jm.idx_q]))
            parent.append(index.get(m.parents[j], -1))
        self.joint_names: List[str] = names
        self._M = np.array(M)                   # (dof, 4, 4)
        self._axes = np.array(axes)             # (dof, 3) unit axes in each joint's frame
        self._prismatic = np.array(prism)
        self._rev = ~self._prismatic
        K = np.array([_skew(a) for a in self._axes])           # cross-product matrices of the axes
        MR = self._M[:, :3, :3]
        self._MK, self._MK2, self._Ma = MR @ K, MR @ K @ K, (MR @ self._axes[:, :, None])[..., 0]
        self.lower = np.array(lo)
        self.upper = np.array(hi)
        bad = [n for n, a, b in zip(names, self.lower, self.upper) if not (np.isfinite(a) and np.isfinite(b) and a < b)]
        if bad:
            raise ValueError(f"urdf: joints {', '.join(bad)} have no finite limits (lower < upper)")
        self._parent = parent
        # the chain's joint ids in pinocchio -> their index in q (for the collision shapes)
        self._joint_slot = index

    # ---- structure ------------------------------------------------------------------------------
    @property
    def dof(self) -> int:
        """Number of joints on the chain (length of q)."""
        return len(self.joint_names)

    @property
    def revolute(self) -> np.ndarray:
        """(dof,) bool: the joints that turn (revolute, continuous); the others slide."""
        return ~self._prismatic

    def set_base(self, base) -> None:
        """The root's pose in the table frame: X, Y, Z, YAW or a 4x4."""
        b = np.asarray(base, dtype=float)
        self.base = _pose4(b, "base") if b.shape == (4, 4) else base_pose(b)

    @property
    def mount(self) -> np.ndarray:
        """4x4: the palm's pose in the flange's frame."""
        return self._mount

    @mount.setter
    def mount(self, value) -> None:
        self._mount = _pose4(value, "mount")
        self._tip = self._flange_in_joint @ self._mount      # the palm in the last joint's frame

    def set_mount(self, mount) -> None:
        """The palm's pose in the flange's frame (4x4)."""
        self.mount = mount

    def check_q(self, q, name: str = "q") -> np.ndarray:
        """q as a finite (B, dof) array; ValueError naming ``name`` otherwise."""
        q = np.asarray(q, dtype=float)
        if q.ndim == 1:
            q = q[None, :]
        if q.ndim != 2 or q.shape[1] != self.dof or not np.all(np.isfinite(q)):
            raise ValueError(f"{name}: expected finite joint values of shape (B, {self.dof}), got {q.shape}")
        return q

    # ---- forward kinematics ---------------------------------------------------------------------
    def _local(self, q: np.ndarray) -> np.ndarray:
        """(B, dof, 4, 4): each joint's frame in its parent's, M_j exp(a_j q_j). For a revolute joint
        Rodrigues, exp = I + sin(q) K + (1 - cos(q)) K^2 (K the axis's cross-product matrix), so that
        M_R exp = M_R + sin(q) M_R K + (1 - cos(q)) M_R K^2 with the products precomputed; a
        prismatic joint adds M_R (q a) to the translation."""
        if self._prismatic.any():
            s = np.where(self._rev, np.sin(q), 0.0)[..., None, None]
            c = np.where(self._rev, 1.0 - np.cos(q), 0.0)[..., None, None]
        else:
            s, c = np.sin(q)[..., None, None], (1.0 - np.cos(q))[..., None, None]
        L = np.repeat(self._M[None], q.shape[0], axis=0)                   # M, its last row 0 0 0 1 included
        L[..., :3, :3] += s * self._MK + c * self._MK2
        if self._prismatic.any():
            L[..., :3, 3] += q[..., None] * np.where(self._prismatic[:, None], self._Ma, 0.0)
        return L

    def _frames(self, q: np.ndarray) -> np.ndarray:
        """(B, dof, 4, 4): the chain's joint frames in the table frame, T_j = T_parent(j) L_j, with
        T of the root = the base (q already checked)."""
        L = self._local(q)
        T = np.empty_like(L)
        for k in range(q.shape[1]):
            T[:, k] = (self.base if self._parent[k] < 0 else T[:, self._parent[k]]) @ L[:, k]
        return T

    def joint_frames(self, q) -> np.ndarray:
        """(B, dof, 4, 4): each chain joint's frame (after its motion) in the table frame."""
        return self._frames(self.check_q(q))

    def flange_poses(self, q) -> np.ndarray:
        """(B, 4, 4): the flange link's frame in the table frame."""
        return self.joint_frames(q)[:, -1] @ self._flange_in_joint

    def palm_poses(self, q) -> np.ndarray:
        """(B, 4, 4): the palm (hand frame) in the table frame: flange * mount."""
        return self.flange_poses(q) @ self.mount

    def palm_jacobian(self, q, checked: bool = False):
        """(palm rotations (B, 3, 3), palm positions (B, 3), J (B, 6, dof)): the palm's pose and its
        spatial Jacobian in the table frame's axes at the palm's origin, rows (linear velocity;
        angular velocity). Column j of a revolute joint is (w_j x (p - o_j); w_j), of a prismatic
        one (w_j; 0), w_j the joint's axis in the table frame and o_j its origin."""
        q = q if checked else self.check_q(q)
        T = self._frames(q)
        Pm = T[:, -1] @ self._tip                                           # the palm, (B, 4, 4)
        Rp, pp = Pm[:, :3, :3], Pm[:, :3, 3]
        w = (T[:, :, :3, :3] @ self._axes[:, :, None])[..., 0]              # (B, dof, 3) axes in the table frame
        r = pp[:, None, :] - T[:, :, :3, 3]
        J = np.empty((q.shape[0], 6, self.dof))
        lin = np.cross(w, r).transpose(0, 2, 1)                             # (B, 3, dof): w x (p - o)
        if self._prismatic.any():
            wt = w.transpose(0, 2, 1)
            J[:, :3] = np.where(self._prismatic, wt, lin)
            J[:, 3:] = np.where(self._prismatic, 0.0, wt)
        else:
            J[:, :3] = lin
            J[:, 3:] = w.transpose(0, 2, 1)
        return Rp, pp, J

    def pin_q(self, q) -> np.ndarray:
        """One chain joint vector (dof,) as pinocchio's configuration vector of the whole model (the
        other joints at zero); for checks against pinocchio's own kinematics."""
        import pinocchio as pin

        qv = self.check_q(q)[0]
        out = pin.neutral(self.model)
        for k, j in enumerate(self._chain):
            jm = self.model.joints[j]
            if jm.nq == 2:
                out[jm.idx_q:jm.idx_q + 2] = [np.cos(qv[k]), np.sin(qv[k])]
            else:
                out[jm.idx_q] = qv[k]
        return out

    # ---- collision shapes -----------------------------------------------------------------------
    def link_shapes(self):
        """The collision shapes that move with the chain: a list of (name, coal geometry, chain
        index of the joint carrying it, 4x4 placement in that joint's frame). Shapes fixed to the
        root (the base, which stands where it is mounted) and shapes of joints off the chain are
        not included."""
        out = []
        for g in self._collision.geometryObjects:
            k = self._joint_slot.get(g.parentJoint)
            if k is not None:
                out.append((g.name, g.geometry, k, np.asarray(g.placement.homogeneous)))
        return out

    def __repr__(self) -> str:
        return f"Arm({Path(self.urdf).name!r}, flange={self.flange!r}, dof={self.dof})"
