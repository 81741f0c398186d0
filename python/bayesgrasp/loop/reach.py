"""The arm in the loop: the reach hooks of the planners that do not know the object's mesh (the
category task, vision then touch), the arm of an episode on disk (``episode new --robot``: stored in
the state at ``new``, loaded again at every open) and the grasp records' ``arm`` (the grasp
schema's, :func:`bayesgrasp.arm.arm_record`). The pose planners' hook is
:class:`bayesgrasp.planners.reach.ActionReach`.

The state's ``arm`` is the URDF (a built-in arm by its name, a file by its absolute path) with the
SHA-256 of its text, the flange link, the base and the mount (4x4 each): an episode opened later
plans with the same arm, and refuses to open when the URDF file changed.
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Optional

import numpy as np

from ..arm import ROBOTS_DIR, Arm, ReachOptions, arm_record, check_reach, resolve_arm


def table_reach(arm: Arm):
    """Eq. 4.1's reach (:attr:`CategoryPlanner.reach`): palm poses (K, 4, 4) -> (K,) bool, the arm
    against the table (the new object's shape is not known, only its view)."""
    return lambda poses: check_reach(arm, poses).reachable


def top_reach(arm: Arm, hand, cloud):
    """Eq. 4.6's reach (:attr:`FusionPlanner.reach`): top grasps (K, 3) -> (K,) bool, each as the palm
    down at (x, y, yaw) at the top of the seen cloud (where a top grasp meets the object at the
    latest), the arm against the table (the new object's mesh is not known, only its cloud)."""
    top = float(np.max(np.asarray(cloud, float)[:, 2])) if len(cloud) else 0.0

    def reach(X):
        P = np.stack([hand.top_grasp_pose(x, y, yaw, top) for x, y, yaw in np.atleast_2d(X)])
        return check_reach(arm, P).reachable
    return reach


def _urdf_sha(path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def arm_state(arm: Arm) -> dict:
    """The arm as the episode's state stores it (JSON)."""
    path = Path(arm.urdf).resolve()
    builtin = path.parent == ROBOTS_DIR.resolve()
    return {"urdf": path.stem if builtin else str(path), "urdf_sha256": _urdf_sha(path), "flange": arm.flange,
            "base": arm.base.tolist(), "mount": arm.mount.tolist()}


def arm_from_state(state: dict, where: str) -> Arm:
    """The stored arm, loaded again; ValueError naming ``where`` (the episode) when its URDF is gone
    or changed since ``new``."""
    try:
        path = resolve_arm(state["urdf"])
    except ValueError:
        raise ValueError(f"{where}: the episode's arm URDF {state['urdf']} is gone") from None
    if _urdf_sha(path) != state["urdf_sha256"]:
        raise ValueError(f"{where}: the arm URDF {path} changed since the episode was started")
    return Arm.load(path, flange=state["flange"], mount=np.asarray(state["mount"], dtype=float),
                    base=np.asarray(state["base"], dtype=float))


def with_arm(arm: Arm, grasp: dict, mesh: Optional[tuple] = None) -> dict:
    """``grasp`` (a grasp-schema record, table frame) with its ``arm``: the grasp checked with the arm
    against the table and ``mesh`` (vertices, faces: the object where the grasp is planned), with the
    record's own pre-grasp distance."""
    r = check_reach(arm, np.asarray(grasp["pose"], dtype=float), mesh,
                    ReachOptions(pregrasp_distance=grasp["pregrasp"]["distance"]))
    return {**grasp, "arm": arm_record(arm, r, 0)}


def with_arm_on(arm: Arm, grasp: dict, obj, pose, hand) -> dict:
    """:func:`with_arm` against the simulated stand-in ``obj`` at ``pose`` (x, y, yaw on the table,
    ``hand`` the world's), or the table alone when ``obj`` is None (a plan on camera data only)."""
    from ..world import World

    mesh = None
    if obj:
        world = World.single(obj, pose=pose, hand=hand)
        mesh = (world.vertices, world.faces)
    return with_arm(arm, grasp, mesh)
