"""Peer benchmark: the same Barrett hand closed on the same mug in pybullet (what a user would
write without our simulator): the hand as a URDF with the same link geometry (written to
bench/results/), the mug as a static concave triangle mesh, a table plane, the finger joints
driven by POSITION_CONTROL towards their closed limits (proximal at 2 rad/s, distal at a third
of that, as the coupling) until every joint velocity stays under 0.01 rad/s for 5 steps (at most
6 s of simulated time; contact jitter on the concave mesh often keeps it from settling). Same grasps as bench_sim (read from
bench/results/sim_grasps.csv, written by `bench_sim --export=bench/results`).

Runs with .venv-bench's python (pybullet, numpy; not bayesgrasp). Writes
bench/results/sim_pybullet.json.

    python bench/sim_pybullet.py [--grasps N] [--results bench/results]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import pybullet as p

ROOT = Path(__file__).resolve().parent.parent
HAND_FILE = ROOT / "python" / "bayesgrasp" / "data" / "hands" / "barrett_bh8.json"
DEG = math.pi / 180
SPEED = 2.0   # proximal closing speed (rad/s); other phalanges at their coupling ratio
STILL = 1e-2  # rad/s: a joint below this for 5 consecutive steps has stopped


def rpy_from_matrix(R):
    """URDF rpy (fixed-axis x, y, z) of a rotation matrix."""
    sy = -R[2, 0]
    pitch = math.asin(max(-1.0, min(1.0, sy)))
    if abs(math.cos(pitch)) > 1e-9:
        roll = math.atan2(R[2, 1], R[2, 2])
        yaw = math.atan2(R[1, 0], R[0, 0])
    else:
        roll, yaw = math.atan2(-R[1, 2], R[1, 1]), 0.0
    return roll, pitch, yaw


def z_to(v):
    """A rotation taking +z to the unit vector v."""
    v = v / np.linalg.norm(v)
    z = np.array([0.0, 0.0, 1.0])
    c = float(z @ v)
    if c > 1 - 1e-12:
        return np.eye(3)
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    a = np.cross(z, v)
    s = np.linalg.norm(a)
    a /= s
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + s * K + (1 - c) * K @ K


def shape_xml(s, flip):
    """Collision + visual of one shape. flip: our link frame is the URDF frame turned by pi
    about x ((x, y, z) -> (x, -y, -z))."""
    F = np.diag([1.0, -1.0, -1.0]) if flip else np.eye(3)
    if s["type"] == "box":
        c = F @ np.asarray(s["center"])
        size = 2 * np.asarray(s["half_extents"])
        geo = f'<box size="{size[0]} {size[1]} {size[2]}"/>'
        origin = f'<origin xyz="{c[0]} {c[1]} {c[2]}" rpy="0 0 0"/>'
    else:
        p0, p1 = F @ np.asarray(s["p0"]), F @ np.asarray(s["p1"])
        c = 0.5 * (p0 + p1)
        length = float(np.linalg.norm(p1 - p0))
        r, pi_, y = rpy_from_matrix(z_to(p1 - p0))
        geo = f'<capsule radius="{s["radius"]}" length="{length}"/>'
        origin = f'<origin xyz="{c[0]} {c[1]} {c[2]}" rpy="{r} {pi_} {y}"/>'
    return f"<collision>{origin}<geometry>{geo}</geometry></collision>"


def link_xml(name, shapes, flip, mass=0.1):
    inertial = (f'<inertial><mass value="{mass}"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" '
                f'izz="1e-4"/></inertial>')
    return f'<link name="{name}">{inertial}{"".join(shape_xml(s, flip) for s in shapes)}</link>'


def hand_urdf(hand):
    """URDF of a hand file (same frames and shapes as the C++ HandModel)."""
    parts = ['<?xml version="1.0"?>', f'<robot name="{hand["name"].split()[0].lower()}">',
             link_xml("palm", hand["palm"]["shapes"], False, 1.0)]
    joints = []  # (name, kind) in pybullet joint order
    for f in hand["fingers"]:
        n, sign = f["name"], f.get("spread_sign", 0.0)
        b = f["base"]
        parts.append(link_xml(f"{n}_knuckle", f.get("knuckle", {}).get("shapes", []), True))
        if sign != 0:
            parts.append(f'<joint name="{n}_spread" type="revolute"><parent link="palm"/><child link="{n}_knuckle"/>'
                         f'<origin xyz="{b[0]} {b[1]} {b[2]}" rpy="0 0 {f["base_yaw_deg"] * DEG}"/>'
                         f'<axis xyz="0 0 {sign}"/><limit lower="{hand["spread"]["lower_deg"] * DEG}" '
                         f'upper="{hand["spread"]["upper_deg"] * DEG}" effort="10" velocity="2"/></joint>')
            joints.append((f"{n}_spread", "spread", None))
        else:
            parts.append(f'<joint name="{n}_spread" type="fixed"><parent link="palm"/><child link="{n}_knuckle"/>'
                         f'<origin xyz="{b[0]} {b[1]} {b[2]}" rpy="0 0 {f["base_yaw_deg"] * DEG}"/></joint>')
        parent, x = f"{n}_knuckle", f.get("knuckle", {}).get("length", 0.0)
        for ph in f["phalanges"]:
            child = f"{n}_{ph['name']}"
            parts.append(link_xml(child, ph.get("shapes", []), True))
            parts.append(f'<joint name="{child}_joint" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                         f'<origin xyz="{x} 0 0" rpy="0 0 0"/><axis xyz="0 -1 0"/>'
                         f'<limit lower="{ph["lower_deg"] * DEG}" upper="{ph["upper_deg"] * DEG}" effort="10" '
                         f'velocity="2"/></joint>')
            joints.append((f"{child}_joint", "phalanx", ph))
            parent, x = child, ph["length"]
    parts.append("</robot>")
    return "\n".join(parts), joints


def quat_from_matrix(R):
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return [x, y, z, w]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--results", default=str(ROOT / "bench" / "results"))
    ap.add_argument("--grasps", type=int, default=64)
    ap.add_argument("--max-steps", type=int, default=1440)
    args = ap.parse_args()
    res = Path(args.results)
    hand = json.loads(HAND_FILE.read_text())
    urdf, joints = hand_urdf(hand)
    (res / "barrett_bh8.urdf").write_text(urdf)
    rows = np.loadtxt(res / "sim_grasps.csv", delimiter=",", comments="#")[: args.grasps]
    J = 1 + sum(len(f["phalanges"]) for f in hand["fingers"])

    p.connect(p.DIRECT)
    p.setGravity(0, 0, 0)  # the hand is position controlled; gravity plays no part in closing
    p.setTimeStep(1 / 240)
    table = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE))
    mug_shape = p.createCollisionShape(p.GEOM_MESH, fileName=str(res / "mug.obj"),
                                       flags=p.GEOM_FORCE_CONCAVE_TRIMESH)
    mug = p.createMultiBody(0, mug_shape)
    robot = p.loadURDF(str(res / "barrett_bh8.urdf"), useFixedBase=True)
    name_to_index = {p.getJointInfo(robot, i)[1].decode(): i for i in range(p.getNumJoints(robot))}
    idx = [name_to_index[n] for n, _, _ in joints]
    kinds = [(k, ph) for _, k, ph in joints]

    times, steps_used, finals = [], [], []
    for row in rows:
        T = row[:16].reshape(4, 4)
        spread = row[16]
        ours = row[17:17 + J]
        t0 = time.perf_counter()
        p.resetBasePositionAndOrientation(robot, T[:3, 3].tolist(), quat_from_matrix(T[:3, :3]))
        targets, vmax, start = [], [], []
        for k, ph in kinds:
            if k == "spread":
                start.append(spread), targets.append(spread), vmax.append(1.0)
            else:
                start.append(ph["offset_deg"] * DEG)
                targets.append(ph["upper_deg"] * DEG)
                vmax.append(SPEED * ph["ratio"])  # rad/s: the coupling's relative speeds
        for j, q0 in zip(idx, start):
            p.resetJointState(robot, j, q0, 0.0)
        for j, tq, v in zip(idx, targets, vmax):
            p.setJointMotorControl2(robot, j, p.POSITION_CONTROL, targetPosition=tq, force=5.0, maxVelocity=v)
        still, n = 0, 0
        for n in range(1, args.max_steps + 1):
            p.stepSimulation()
            vel = [s[1] for s in p.getJointStates(robot, idx)]
            still = still + 1 if max(abs(v) for v in vel) < STILL else 0
            if still >= 5:
                break
        q = [s[0] for s in p.getJointStates(robot, idx)]
        times.append(time.perf_counter() - t0)
        steps_used.append(n)
        # our joint layout: spread then phalanges in order (spread joints of both fingers = q[0])
        qq = [spread] + [qv for (k, _), qv in zip(kinds, q) if k != "spread"]
        finals.append(np.abs(np.array(qq[1:]) - ours[1:]) / DEG)
    p.disconnect()
    times = np.array(times)
    diffs = np.concatenate(finals)
    out = {
        "peer": f"pybullet {p.getAPIVersion()} POSITION_CONTROL closing, DIRECT mode, 240 Hz",
        "grasps": int(len(rows)),
        "median_ms_per_grasp": float(np.median(times) * 1e3),
        "grasps_per_s": float(1.0 / np.median(times)),
        "median_steps": float(np.median(steps_used)),
        "max_steps_hit": int(np.sum(np.array(steps_used) >= args.max_steps)),
        "joint_diff_vs_ours_deg": {"median": float(np.median(diffs)), "p90": float(np.percentile(diffs, 90))},
    }
    (res / "sim_pybullet.json").write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
