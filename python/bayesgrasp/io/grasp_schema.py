"""One grasp schema for every command's output (``data/schema/grasp.schema.json``), and the same
grasp shaped like ROS messages (``moveit_msgs/Grasp`` with a ``sensor_msgs/JointState``).

A grasp record holds where the hand closes and how it gets there; what happened (lifted,
epsilon, contacts) is kept beside it by the caller::

    rec = grasp_record(hand_pose, hand="barrett_bh8", joint_names=names, joint_positions=q,
                       spread=0.0, open_positions=q_open)
    validate(rec)            # jsonschema against the shipped schema
    to_ros(rec)              # moveit_msgs/Grasp-shaped dict
"""
from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

SCHEMA_PATH = Path(__file__).resolve().parents[1] / "data" / "schema" / "grasp.schema.json"
PREGRASP_DISTANCE = 0.10   # m backed off along -approach before the final move
LIFT_DISTANCE = 0.10       # m of the lift after closing (the lift test's)
FRAMES = ("world", "object")


def quaternion_xyzw(R) -> list:
    """Unit quaternion (x, y, z, w) of a rotation matrix, with w >= 0."""
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(np.asarray(R, dtype=float)).as_quat()   # scipy's order is (x, y, z, w)
    return (-q if q[3] < 0 else q).tolist()


def _rigid(pose) -> np.ndarray:
    T = np.asarray(pose, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ValueError(f"pose: expected a finite 4x4 matrix, got shape {T.shape}")
    R = T[:3, :3]
    if not (np.allclose(R.T @ R, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0 and np.allclose(T[3], [0, 0, 0, 1])):
        raise ValueError("pose: not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)")
    return T


def grasp_record(pose, hand: str, joint_names: Sequence[str], joint_positions, spread: float,
                 frame: str = "world", open_positions=None, pregrasp_distance: float = PREGRASP_DISTANCE) -> dict:
    """The schema's grasp: ``pose`` the 4x4 hand pose where the fingers close (its +z is the
    approach), the pre-grasp ``pregrasp_distance`` back along the approach with the hand open
    (``open_positions``; default: the closed positions)."""
    if frame not in FRAMES:
        raise ValueError(f"frame: 'world' or 'object', got {frame!r}")
    T = _rigid(pose)
    q = np.asarray(joint_positions, dtype=float).ravel()
    names = [str(n) for n in joint_names]
    if len(names) != q.size:
        raise ValueError(f"joint_positions: {q.size} values for {len(names)} joint names")
    q_open = q if open_positions is None else np.asarray(open_positions, dtype=float).ravel()
    if q_open.size != q.size:
        raise ValueError(f"open_positions: {q_open.size} values for {len(names)} joint names")
    if not (np.isfinite(pregrasp_distance) and pregrasp_distance >= 0):
        raise ValueError(f"pregrasp_distance: must be >= 0 (m), got {pregrasp_distance}")
    approach = T[:3, 2] / np.linalg.norm(T[:3, 2])
    P = T.copy()
    P[:3, 3] = T[:3, 3] - pregrasp_distance * approach
    return {"frame": frame, "pose": T.tolist(), "position": T[:3, 3].tolist(), "quaternion_xyzw": quaternion_xyzw(T[:3, :3]),
            "approach": approach.tolist(),
            "pregrasp": {"pose": P.tolist(), "distance": float(pregrasp_distance), "joint_positions": q_open.tolist()},
            "hand": str(hand), "joint_names": names, "joint_positions": q.tolist(), "spread": float(spread)}


def hand_grasp_record(hand, pose, joint_positions, spread: Optional[float], frame: str = "world") -> dict:
    """:func:`grasp_record` for a :class:`bayesgrasp.hand.Hand`: its name, joint names and open
    preshape; a URDF hand's record also gives them in the URDF's terms (``urdf``)."""
    s = float(hand.core.spread_default if spread is None else spread)
    q_open = hand.open_joints(s)
    rec = grasp_record(pose, hand.name, hand.joint_names, joint_positions, s, frame=frame, open_positions=q_open)
    closed = hand.urdf_joints(rec["joint_positions"])
    if closed is not None:
        rec["urdf"] = {"joint_names": closed[0], "joint_positions": closed[1].tolist(),
                       "pregrasp_joint_positions": hand.urdf_joints(q_open)[1].tolist()}
    return rec


@lru_cache(maxsize=1)
def schema() -> dict:
    return json.loads(SCHEMA_PATH.read_text())


def validate(record: dict) -> None:
    """Raises jsonschema.ValidationError when ``record`` is not a grasp of the schema."""
    import jsonschema

    jsonschema.validate(record, schema())


# ---- ROS-shaped output ------------------------------------------------------------------------------
def _pose_msg(position, quaternion) -> dict:
    x, y, z = position
    qx, qy, qz, qw = quaternion
    return {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}}


def _trajectory(names, positions, seconds: float, frame_id: str) -> dict:
    """trajectory_msgs/JointTrajectory with one point."""
    sec = int(seconds)
    return {"header": {"frame_id": frame_id}, "joint_names": list(names),
            "points": [{"positions": list(positions), "velocities": [], "accelerations": [], "effort": [],
                        "time_from_start": {"sec": sec, "nanosec": int(round((seconds - sec) * 1e9))}}]}


def _arm_trajectory(arm: dict, frame_id: str) -> dict:
    """trajectory_msgs/JointTrajectory of the arm from its pre-grasp joints (0 s) to its grasp joints
    (1 s): the two ends of the straight approach the reach check walked."""
    pre, grasp = (_trajectory(arm["joint_names"], arm[k], t, frame_id)
                  for k, t in (("pregrasp_joint_positions", 0.0), ("joint_positions", 1.0)))
    pre["points"] += grasp["points"]
    return pre


def _translation(frame_id: str, vector, distance: float) -> dict:
    """moveit_msgs/GripperTranslation."""
    x, y, z = (float(v) for v in vector)
    return {"direction": {"header": {"frame_id": frame_id}, "vector": {"x": x, "y": y, "z": z}},
            "desired_distance": float(distance), "min_distance": float(distance) / 2}


def to_ros(record: dict, grasp_id: str = "grasp", quality: Optional[float] = None,
           lift: float = LIFT_DISTANCE) -> dict:
    """``record`` shaped like ``moveit_msgs/Grasp`` (plus ``joint_state``, a
    ``sensor_msgs/JointState`` of the closed hand). The approach is given in the hand's frame
    (its +z, as MoveIt expects it in the end effector's frame), the retreat is the lift: +z of
    the record's frame. The frame_id is the record's frame ("world" or "object"). A record whose
    ``arm`` reaches the grasp also gets ``arm_trajectory``, a ``trajectory_msgs/JointTrajectory`` of
    the arm's joints from the pre-grasp to the grasp."""
    frame_id = record["frame"]
    pre = record["pregrasp"]
    if "urdf" in record:        # a URDF hand: the joints the robot's driver knows, in its terms
        names, closed, opened = (record["urdf"][k] for k in ("joint_names", "joint_positions", "pregrasp_joint_positions"))
    else:
        names, closed, opened = record["joint_names"], record["joint_positions"], pre["joint_positions"]
    out = {"id": grasp_id,
           "pre_grasp_posture": _trajectory(names, opened, 0.0, frame_id),
           "grasp_posture": _trajectory(names, closed, 1.0, frame_id),
           "grasp_pose": {"header": {"frame_id": frame_id},
                          "pose": _pose_msg(record["position"], record["quaternion_xyzw"])},
           "grasp_quality": 0.0 if quality is None else float(quality),
           "pre_grasp_approach": _translation("hand", (0.0, 0.0, 1.0), pre["distance"]),
           "post_grasp_retreat": _translation(frame_id, (0.0, 0.0, 1.0), lift),
           "post_place_retreat": _translation(frame_id, (0.0, 0.0, 0.0), 0.0),
           "max_contact_force": 0.0, "allowed_touch_objects": [],
           "joint_state": {"header": {"frame_id": frame_id}, "name": list(names),
                           "position": list(closed), "velocity": [], "effort": []}}
    if record.get("arm", {}).get("reachable"):
        out["arm_trajectory"] = _arm_trajectory(record["arm"], frame_id)
    return out
