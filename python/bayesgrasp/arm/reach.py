"""Can the arm reach these grasps? One batched call for N palm poses.

    result = check_reach(arm, palm_poses, object_mesh=mesh)        # palm_poses (N, 4, 4), table frame
    result.reachable, result.reason, result.q, result.q_pre, result.joint_names

A grasp is reachable when the arm has a joint vector within its limits that puts the palm at the
grasp pose, another at the pre-grasp (the palm backed off along its approach, -z of the hand
frame, by ``pregrasp_distance``), and one at every step of the straight line between them, each
step's IK started from the grasp's solution and no joint moving by more than ``max_joint_step``
from one step to the next, with no link of the arm in the table or the object at any of them.

The steps, each batched over the candidates still open:

1. ``seed_round``: IK of the grasp pose from its ``seeds`` starts, the joint vectors of a seeded
   library whose palm poses lie nearest it (:mod:`.starts`); round 0 from the nearest for every
   grasp (FIRST_ROUND_ITERATIONS steps), round 1 from the others at once for the grasps round 0
   left open, round 0's unconverged problems going on beside them;
2. ``grasp_collisions``: every converged solution against the table and the object;
3. ``walk_approach``: the approach line from the grasp back to the pre-grasp at steps, each step's
   IK warm-started from the grasp's solution, for every collision-free solution at once; a grasp
   takes its first solution (nearest start first) whose walk holds;
4. ``diagnose_limits``: a grasp that round 0 could not solve is also solved in round 1's batch
   from its first three starts with the limits lifted; if no start solves it within the limits
   and a lifted solve lands outside them, the reason is "joint limits", else "no IK solution".

A grasp's reason is the first collision met ("arm hits table", "arm hits object"), else what
step 4 finds.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import List, Optional

import numpy as np

from .collision import FREE, HITS_OBJECT, HITS_TABLE, ArmCollision
from .ik import pose_error, solve_ik
from .starts import nearest_starts

__all__ = ["ReachOptions", "ReachResult", "arm_record", "check_reach", "REASONS"]

NO_IK, HITS_TABLE_REASON, HITS_OBJECT_REASON, JOINT_LIMITS = (
    "no IK solution", "arm hits table", "arm hits object", "joint limits")
REASONS = (NO_IK, HITS_TABLE_REASON, HITS_OBJECT_REASON, JOINT_LIMITS)
_COLLISION_REASON = {HITS_TABLE: HITS_TABLE_REASON, HITS_OBJECT: HITS_OBJECT_REASON}
#: steps of round 0 (from each grasp's nearest start); its unconverged problems continue in round 1
FIRST_ROUND_ITERATIONS = 20


@dataclass(frozen=True)
class ReachOptions:
    """Settings of :func:`check_reach` (metres, radians); validated when made."""

    seeds: int = 8                   # IK starts per grasp: the nearest entries of a seeded library (.starts)
    seed: int = 0                    # the generator of the start library
    iterations: int = 60             # damped-least-squares steps per start (round 0: at most 20, then on in round 1)
    damping: float = 0.05            # lambda of the damped least squares
    max_step: float = 0.3            # rad (m for a prismatic joint): largest joint change per IK step
    tol_position: float = 1e-4       # m: the palm's position error accepted
    tol_rotation: float = 1e-3       # rad: the palm's orientation error accepted
    position_only: bool = False      # solve for the palm's position only (an arm of fewer than six joints)
    pregrasp_distance: float = 0.1   # m: the pre-grasp, backed off along the approach
    approach_steps: int = 5          # intervals of the straight line from the grasp to the pre-grasp
    step_iterations: int = 15        # IK steps per approach pose (warm-started from the grasp's solution)
    max_joint_step: float = 0.5      # rad: largest joint change between approach poses (more: the IK jumped)
    table: bool = True               # check the links against the table (z < 0)
    clearance: float = 0.0           # m: the gap a link keeps from the table and the object

    def __post_init__(self):
        for name in ("seeds", "iterations", "approach_steps", "step_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ValueError(f"{name}: must be an integer >= 1, got {v!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**63:
            raise ValueError(f"seed: must be an integer in [0, 2**63), got {self.seed!r}")
        for name in ("damping", "max_step", "tol_position", "tol_rotation", "max_joint_step"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.floating)) and np.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be a finite number > 0, got {v!r}")
        for name in ("pregrasp_distance", "clearance"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.floating)) and np.isfinite(v) and v >= 0):
                raise ValueError(f"{name}: must be a finite number >= 0 (m), got {v!r}")

    def with_(self, **kw) -> "ReachOptions":
        return replace(self, **kw)


@dataclass
class ReachResult:
    """Reachability of N palm poses.

    reachable : (N,) bool, the grasp, its pre-grasp and the approach between them are reachable
    reason : list of N str, "" when reachable, else one of REASONS
    q : (N, dof) joint values at the grasp in ``joint_names``' order (the URDF's), NaN when unreachable
    q_pre : (N, dof) joint values at the pre-grasp, NaN when unreachable
    joint_names : the arm's joints, the URDF's names in its order
    position_error : (N,) m, the palm's position error at q (NaN when unreachable)
    rotation_error : (N,) rad, the palm's orientation error at q (NaN when unreachable)
    seconds : float, the call's wall time
    counts : dict, ``ik_problems``: the grasp IK problems solved (grasps x starts tried)
    """

    reachable: np.ndarray
    reason: List[str]
    q: np.ndarray
    q_pre: np.ndarray
    joint_names: List[str]
    position_error: np.ndarray
    rotation_error: np.ndarray
    seconds: float = 0.0
    counts: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        def rows(a):
            return [None if not np.all(np.isfinite(r)) else [float(x) for x in r] for r in a]

        return {"reachable": [bool(x) for x in self.reachable], "reason": list(self.reason),
                "joint_names": list(self.joint_names), "q": rows(self.q), "q_pre": rows(self.q_pre),
                "position_error": [float(x) for x in self.position_error],
                "rotation_error": [float(x) for x in self.rotation_error], "seconds": float(self.seconds)}


def _palm_poses(palm_poses) -> np.ndarray:
    P = np.asarray(palm_poses, dtype=float)
    if P.shape == (4, 4):
        P = P[None]
    if P.ndim != 3 or P.shape[1:] != (4, 4) or len(P) == 0:
        raise ValueError(f"palm_poses: expected (N, 4, 4) palm poses in the table frame, got shape {P.shape}")
    if not np.all(np.isfinite(P)):
        raise ValueError("palm_poses: not finite")
    R = P[:, :3, :3]
    bad = (~np.all(np.isclose(R @ R.transpose(0, 2, 1), np.eye(3), atol=1e-6), axis=(1, 2))
           | ~np.isclose(np.linalg.det(R), 1, atol=1e-6) | ~np.all(np.isclose(P[:, 3], [0, 0, 0, 1]), axis=1))
    if bad.any():
        raise ValueError(f"palm_poses[{int(np.flatnonzero(bad)[0])}]: not a rigid transform (rotation not orthonormal "
                         "or last row not 0 0 0 1)")
    return P


def _backed_off(P: np.ndarray, d: float) -> np.ndarray:
    """The palm poses moved by d along -z of their own frame (back along the approach)."""
    out = P.copy()
    out[:, :3, 3] -= d * P[:, :3, 2]
    return out


def _ik(arm, target, q0, options: ReachOptions, iterations: int, limits: bool = True):
    return solve_ik(arm, target, q0, iterations=iterations, damping=options.damping, max_step=options.max_step,
                    tol_position=options.tol_position, tol_rotation=options.tol_rotation,
                    position_only=options.position_only, limits=limits)


def walk_approach(arm, P: np.ndarray, q_grasp: np.ndarray, scene: ArmCollision, options: ReachOptions):
    """The straight line from the grasp poses P (B, 4, 4) back to their pre-grasps, at
    ``approach_steps`` intervals. Every step's IK is warm-started from the grasp's solution, all steps
    of all grasps in one batch; the walk holds when every step converges, no joint moves more than
    ``max_joint_step`` between consecutive steps (else the IK left the grasp's branch) and no step
    collides. Returns (ok (B,), q at the pre-grasp (B, dof), code of the first collision met (B,))."""
    B, K = len(P), options.approach_steps
    steps = np.concatenate([_backed_off(P, options.pregrasp_distance * k / K) for k in range(1, K + 1)])  # (K B)
    sol = _ik(arm, steps, np.tile(q_grasp, (K, 1)), options, options.step_iterations)
    qs = np.concatenate([q_grasp[None], sol.q.reshape(K, B, -1)])                       # (K + 1, B, dof)
    conv = sol.converged.reshape(K, B).all(axis=0)
    smooth = (np.abs(np.diff(qs, axis=0)).max(axis=2) <= options.max_joint_step).all(axis=0)
    code = np.full(B, FREE)
    ok = conv & smooth
    if ok.any():
        c = scene.check(sol.q.reshape(K, B, -1)[:, ok].reshape(-1, arm.dof)).reshape(K, -1)   # step by step
        hit = c != FREE
        first = np.where(hit.any(axis=0), c[hit.argmax(axis=0), np.arange(c.shape[1])], FREE)
        code[ok] = first
        ok[ok] = ~hit.any(axis=0)
    return ok, qs[-1], code


def check_reach(arm, palm_poses, object_mesh=None, options: Optional[ReachOptions] = None) -> ReachResult:
    """Reachability of N palm poses (N, 4, 4) in the table frame by ``arm`` (an :class:`Arm`, its base
    and mount set), the object's mesh (trimesh or (vertices, faces), table frame; None: the table
    only). See the module's docstring for the steps."""
    import time

    t0 = time.perf_counter()
    options = options or ReachOptions()
    if not isinstance(options, ReachOptions):
        raise ValueError(f"options: expected a ReachOptions, got {type(options).__name__}")
    P = _palm_poses(palm_poses)
    scene = ArmCollision(arm, object_mesh, table=options.table, clearance=options.clearance)
    N, n = len(P), arm.dof
    starts = nearest_starts(arm, P, options.seeds, options.seed, options.position_only)   # (N, seeds, dof)
    state = _State(N, n)
    # 1. seed_round. Round 0 from each grasp's nearest start (FIRST_ROUND_ITERATIONS steps: most
    # converge well within them); round 1 from its other starts at once for the grasps round 0 left
    # open, beside round 0's unconverged problems going on where they stopped, and beside those it
    # could not solve from their first three starts with the limits lifted (for 4. diagnose_limits)
    idx = np.arange(N)
    first = min(options.iterations, FIRST_ROUND_ITERATIONS)
    sol = _ik(arm, P, starts[:, 0], options, first)
    state.counts["ik_problems"] += N
    state.solved[sol.converged] = True
    _accept(arm, P, idx[sol.converged], sol.q[sol.converged], scene, options, state)
    q_first = sol.q                             # round 0's unconverged problems go on from here in round 1
    idx = np.flatnonzero(~state.done)
    free = np.zeros((0, n))
    if idx.size:
        unsolved = idx[~state.solved[idx]]      # only these may need the diagnosis
        rows, lifted = starts[idx, 1:], starts[unsolved, :3]
        cand = np.r_[np.repeat(idx, rows.shape[1]), unsolved, np.repeat(unsolved, lifted.shape[1])].astype(int)
        q0 = np.r_[rows.reshape(-1, n), q_first[unsolved], lifted.reshape(-1, n)]
        held = np.r_[np.ones(rows.shape[0] * rows.shape[1] + unsolved.size, dtype=bool),
                     np.zeros(lifted.shape[0] * lifted.shape[1], dtype=bool)]
        sol = _ik(arm, P[cand], q0, options, options.iterations, limits=held)
        state.counts["ik_problems"] += cand.size
        conv = sol.converged & held
        state.solved[cand[conv]] = True
        _accept(arm, P, cand[conv], sol.q[conv], scene, options, state)
        lift = sol.converged & ~held
        state.lifted_cand, free = cand[lift], sol.q[lift]
    reason = _reasons(arm, N, free, state)
    pe, re = np.full(N, np.nan), np.full(N, np.nan)
    d = state.done
    if d.any():
        Pq = arm.palm_poses(state.q[d])
        e = pose_error(P[d, :3, :3], P[d, :3, 3], Pq[:, :3, :3], Pq[:, :3, 3], options.position_only)
        pe[d], re[d] = np.linalg.norm(e[:, :3], axis=1), np.linalg.norm(e[:, 3:], axis=1)
    return ReachResult(d, reason, state.q, state.q_pre, list(arm.joint_names), pe, re,
                       time.perf_counter() - t0, state.counts)


class _State:
    """What the rounds have found so far, per grasp."""

    def __init__(self, N: int, n: int):
        self.done = np.zeros(N, dtype=bool)          # reachable, with q and q_pre
        self.q, self.q_pre = np.full((N, n), np.nan), np.full((N, n), np.nan)
        self.code = np.full(N, FREE)                 # the first collision met (FREE: none yet)
        self.solved = np.zeros(N, dtype=bool)        # some start's IK converged at the grasp
        self.counts = {"ik_problems": 0}
        self.lifted_cand = np.zeros(0, dtype=int)      # grasps solved with the limits lifted

    def collided(self, cand: np.ndarray, code: np.ndarray) -> None:
        hit = code != FREE
        first = hit & (self.code[cand] == FREE)
        self.code[cand[first]] = code[first]


def _accept(arm, P, cand: np.ndarray, q: np.ndarray, scene: ArmCollision, options: ReachOptions,
            state: _State) -> None:
    """Converged grasp solutions (cand (K,) grasp indices in start order, q (K, dof)) of grasps not
    done yet: 2. grasp_collisions on all of them, then 3. walk_approach from every collision-free
    one in one batch; a grasp is done with its first solution whose walk held."""
    if cand.size == 0:
        return
    c = scene.check(q)                                # 2. grasp_collisions
    state.collided(cand, c)
    cand, q = cand[c == FREE], q[c == FREE]
    if cand.size == 0:
        return
    ok, qp, pc = walk_approach(arm, P[cand], q, scene, options)     # 3. walk_approach, all at once
    state.collided(cand, pc)
    # each grasp takes its first solution (in start order) whose walk held
    first = np.flatnonzero(ok)
    g, k = np.unique(cand[first], return_index=True)
    k = first[k]
    state.done[g] = True
    state.q[g], state.q_pre[g] = q[k], qp[k]


def _reasons(arm, N: int, lifted_q: np.ndarray, state: _State) -> List[str]:
    """Each grasp's reason: "" when reachable, else its first collision, else 4. diagnose_limits: a
    grasp no start could solve within the limits but that the lifted solves reached
    (``state.lifted_cand``, ``lifted_q``) at joint values outside the limits (revolute angles
    wrapped to (-pi, pi]) is "joint limits", else "no IK solution"."""
    reason = np.array([""] * N, dtype=object)
    hit = ~state.done & (state.code != FREE)
    reason[hit] = [_COLLISION_REASON[int(c)] for c in state.code[hit]]
    rest = ~state.done & (state.code == FREE)
    reason[rest] = NO_IK
    if state.lifted_cand.size:
        qw = np.where(arm.revolute, np.mod(lifted_q + np.pi, 2 * np.pi) - np.pi, lifted_q)
        beyond = np.any((qw < arm.lower) | (qw > arm.upper), axis=1)
        g = np.unique(state.lifted_cand[beyond])
        g = g[rest[g] & ~state.solved[g]]
        reason[g] = JOINT_LIMITS
    return [str(x) for x in reason]


def arm_record(arm, result: ReachResult, i: int = 0) -> dict:
    """Grasp i of ``result`` in the robot's terms, the grasp schema's ``arm``: the URDF, the base (4x4
    in the table frame), the flange link, the mount (4x4, flange to palm), the URDF's joint names and,
    when reachable, their values at the grasp and at the pre-grasp; else the reason."""
    rec = {"urdf": str(arm.urdf), "base": arm.base.tolist(), "flange_link": arm.flange, "mount": arm.mount.tolist(),
           "joint_names": list(result.joint_names), "reachable": bool(result.reachable[i]), "reason": result.reason[i]}
    if result.reachable[i]:
        rec["joint_positions"] = [float(v) for v in result.q[i]]
        rec["pregrasp_joint_positions"] = [float(v) for v in result.q_pre[i]]
    return rec
