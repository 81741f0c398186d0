"""Judge the peer planners' grasps with our own lift test (issue 52, part 2a).

Run with our python, from the repository root:

    nice -n 10 .venv/bin/python bench/peers/judge.py                  # both YCB objects at (0, 0, 0)
    nice -n 10 .venv/bin/python bench/peers/judge.py --check-frames   # only the frame check
    .venv/bin/python bench/peers/judge.py --reuse                     # keep peer results already on disk

For each object (a YCB mesh in metres, object frame z up resting on z = 0) at a planar pose on
the table, this script

1. runs the peer drivers in their own virtual environments, through subprocess:
   pybullet-grasper (`.venv-peer-pbg`, hand "barrett") on the mesh, and cgn-pytorch
   (`.venv-peer-cgn`) on a partial cloud from `make_partial_cloud.py` (run by `.venv-peer-pbg`'s
   python, which has Open3D); each returns its top 5 grasps as 4x4 poses in the table frame;
2. converts each grasp into our hand's frame (the palm frame "where the fingers close", +z the
   approach): pybullet-grasper's Barrett base link -> our `barrett_bh8`
   (:func:`pbg_barrett_to_bh8`), Contact-GraspNet's Panda frame -> our `parallel_jaw.urdf`
   (:func:`cgn_panda_to_parallel_jaw`);
3. (``--check-frames``, and always before judging) compares finger points of the peer's hand at
   its pose, from the peer's own kinematics, with ours at the converted pose (:func:`check_frames`);
4. closes our hand at each converted pose in our World (same mesh, same pose, the mesh's own
   origin kept) and lift-tests it; writes `judge.json` and prints top-1 / top-5 lifted per peer
   and object, and the peers' wall times.

pybullet-grasper's top 5 are its tested candidates ranked by its own score, whether or not any of
them held in its own lift and shake (its verdict is kept beside ours as `peer_lift_test`).
Contact-GraspNet's top 5 are its most confident grasps; it has no test of its own.

Our object: the same mesh loaded with its YCB mass (mug 0.118 kg, soup can 0.349 kg: the YCB
set's published masses, as in README.md's "Bring a scan"), placed with ``keep_origin=True`` so its
xy origin is the mesh file's. Our scene also lifts the mesh so that its lowest point is at z = 0
(the mug's lowest vertex is at z = -0.53 mm, the can's at +0.08 mm); the hand poses are moved by
the same vertical offset so that the hand stays where the peer put it relative to the object.

Nothing is downloaded; outputs go to `bench/results/peers_judge/` (git ignores `bench/results/`).
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
PEERS = REPO / "bench" / "peers"
PBG_PYTHON = REPO / ".venv-peer-pbg" / "bin" / "python"
CGN_PYTHON = REPO / ".venv-peer-cgn" / "bin" / "python"
OUT_DEFAULT = REPO / "bench" / "results" / "peers_judge"

# name -> (mesh, mass in kg: the YCB set's published masses, README.md "Bring a scan")
OBJECTS = {
    "025_mug": ("tests/data/ycb/025_mug.stl", 0.118),
    "005_tomato_soup_can": ("tests/data/ycb/005_tomato_soup_can.stl", 0.349),
}
TOP_K = 5
#: peer -> our hand its grasps are executed with. "pybullet_grasper" closes the peer's Barrett,
#: "pybullet_grasper_2f85" its Robotiq 2F-85, "cgn" Contact-GraspNet's Panda jaws.
OUR_HAND = {"pybullet_grasper": "barrett_bh8", "pybullet_grasper_2f85": "parallel_jaw.urdf",
            "cgn": "parallel_jaw.urdf"}
PEER_NAMES = tuple(OUR_HAND)

# ---- geometry of the peers' hands (facts, with where they were read) -----------------------------
# pybullet-grasper's Barrett: .venv-peer-pbg/share/pybullet_grasper/grippers/barrett_hand/barrett_hand.urdf
# Joint origins (xyz, rpy) and axes, parent -> child:
PBG_J32 = ((0.0, -0.05, 0.0754), (1.5708, 0.0, 1.5708), (0, 0, -1))        # base -> finger 3 proximal
PBG_J11 = ((0.025, 0.0, 0.0415), (0.0, 0.0, -1.5708), (0, 0, -1))          # base -> finger 1 knuckle (spread)
PBG_J21 = ((-0.025, 0.0, 0.0415), (0.0, 0.0, -1.5708), (0, 0, 1))          # base -> finger 2 knuckle (spread)
PBG_J12 = ((-0.05, 0.0, 0.0339), (1.5708, 0.0, 0.0), (0, 0, -1))           # knuckle -> proximal (fingers 1, 2)
PBG_JDIST = ((-0.069936, 0.003, 0.0), (0.0, 0.0, 0.0), (0, 0, -1))         # proximal -> distal (all fingers)
# The fingertip in the distal link's frame: the vertex of visual/finger_tip_33.obj farthest from
# the distal joint (0.059 m out, the tip bent about 36 degrees towards the palm side).
PBG_TIP = (-0.0477, 0.0349, 0.0)
PBG_SPREAD = 0.01   # rad, bh_j11 (and bh_j21 by mimic) held there by the peer (driver docstring)
# The palm face in bh_base_link: z = 0.079 m at the centre of the palm (visual/palm_280.obj, every
# vertex within 30 mm of the z axis is at z <= 0.0793; the collision hull palm_280_vhacd.obj
# reaches 0.0797 there). 0.090 m, the highest point near the centre, is the top of finger 3's housing
# (x within +/-12.5 mm, y from -0.060 to -0.038 m), not the palm face under the object.
PBG_PALM_FACE_Z = 0.079

# Contact-GraspNet's Panda (cgn_driver.py docstring and cgn_pytorch/util/mesh_utils.py):
# origin at the gripper base; fingertips' centre gripper_depth = 0.1034 m out along +z; the
# fingers' joints at z = 0.0584 m (mesh_utils.get_control_point_tensor, convex_hull=False);
# open fingers at +/- gripper_width / 2 = 0.04 m along +x (inference()'s gripper_width 0.08).
CGN_DEPTH = 0.1034
CGN_JOINT_Z = 0.0584
CGN_HALF_OPEN = 0.04

# Our parallel_jaw.urdf (+ .hand.json): palm frame = pj_hand + (0, 0, 0.0584) (sidecar "palm");
# jaws along the palm's y (joint axis y, pj_finger_joint2 turned by pi about z), the open jaws'
# pads on the planes y = +/-0.04 m (the finger mesh's pad is its link's plane y = 0); the
# fingers run 0.054 m out along +z from the palm frame.
PJ_PALM_Z = 0.0584
# The middle of our jaws' pads along the approach, from the palm frame (the jaw is 0.054 m long).
PJ_PAD_MID = 0.027

# pybullet-grasper's Robotiq 2F-85 (pybullet_grasper_driver.py docstring, read from its URDF):
# base link at the coupling face, +z out through the fingers, the open pads (left_contactile,
# right_contactile) at z = 0.150 m, y = -/+0.0487 m, closing along y.
PBG_2F85_PAD_Z = 0.150
PBG_2F85_PAD_Y = 0.0487


def trans(x, y, z):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def rot_axis(axis, angle):
    """4x4 rotation by `angle` about the unit `axis` (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * (K @ K)
    return T


def rpy(r, p, y):
    """URDF's fixed-axis roll-pitch-yaw: Rz(y) Ry(p) Rx(r)."""
    return rot_axis((0, 0, 1), y) @ rot_axis((0, 1, 0), p) @ rot_axis((1, 0, 0), r)


def urdf_joint(joint, q):
    """Parent -> child transform of a URDF revolute joint (origin xyz, rpy, axis) at angle q."""
    xyz, angles, axis = joint
    return trans(*xyz) @ rpy(*angles) @ rot_axis(axis, q)


# ---- the conversions ---------------------------------------------------------------------------
def pbg_barrett_to_bh8(T_base):
    """pybullet-grasper's Barrett pose -> our `barrett_bh8` hand pose (both 4x4, table frame).

    Peer: `pose` is `bh_base_link` at closing, +z the approach; finger 3 (thumb) on -y, its
    proximal joint bh_j32 at (0, -0.05, 0.0754); fingers 1 and 2 at x = +0.025 / -0.025, their
    proximal joints at y = +0.05, z = 0.0754 (barrett_hand.urdf, bh_j11/bh_j21 at z 0.0415 plus
    bh_j12/bh_j22 0.0339 above); the palm face at the centre at z = 0.079 (visual/palm_280.obj).
    Ours (barrett_bh8.json): origin at the centre of the palm face, +z out of the palm, finger 3
    on -y (base yaw -90 deg, knuckle 0.05: proximal joint at (0, -0.05, 0)), finger 1 at
    x = +0.025 and finger 2 at x = -0.025, proximal joints at y = +0.05 (base yaw +90 deg,
    knuckle 0.05).
    So the axes already agree (no turn about the approach: thumb -y to -y, finger 1 +x to +x) and
    our palm frame is the peer's base link moved 0.079 m along its +z. The proximal joints then
    sit 3.6 mm apart along the approach (ours in the palm face, the peer's 0.0754 m up).
    """
    return np.asarray(T_base, dtype=float) @ trans(0.0, 0.0, PBG_PALM_FACE_Z)


def cgn_panda_to_parallel_jaw(T_cgn):
    """Contact-GraspNet's Panda pose -> our `parallel_jaw.urdf` hand pose (both 4x4, table frame).

    Peer (cgn_driver.py docstring, cgn_pytorch mesh_utils): origin at the gripper base, +z the
    approach, +x the closing direction; the finger joints at z = 0.0584 m, the fingertips' centre
    at z = 0.1034 m, the open fingers at x = +/-0.04 m.
    Ours (parallel_jaw.urdf and parallel_jaw.hand.json): the hand frame is link `pj_hand` (the
    flange side, as the Panda's base) moved 0.0584 m along +z (the sidecar's palm xyz, where the
    jaw joints are), +z the approach; the jaws close along our y (the prismatic axis), the open
    pads at y = +/-0.04 m. The Panda's fingertips' centre is 0.1034 - 0.0584 = 0.045 m out in ours.
    So ours = peer @ Trans(0, 0, 0.0584) @ Rz(+90 deg): our +y is the peer's -x (our left jaw on
    the peer's -x finger, where cgn's predicted contact is), our +x the peer's +y, +z unchanged.
    """
    return np.asarray(T_cgn, dtype=float) @ trans(0.0, 0.0, PJ_PALM_Z) @ rot_axis((0, 0, 1), np.pi / 2)


def pbg_robotiq_to_parallel_jaw(T_base):
    """pybullet-grasper's Robotiq 2F-85 pose -> our `parallel_jaw.urdf` hand pose (4x4, table frame).

    Both close along their y axis with +z the approach, so no turn; our palm frame goes where our
    pads' middle (PJ_PAD_MID out) meets the peer's pads (PBG_2F85_PAD_Z out). The open widths
    differ (the 2F-85's pads 97.4 mm apart, ours 80 mm): each of our open pads is 8.7 mm inside.
    """
    return np.asarray(T_base, dtype=float) @ trans(0.0, 0.0, PBG_2F85_PAD_Z - PJ_PAD_MID)


CONVERT = {"pybullet_grasper": pbg_barrett_to_bh8, "pybullet_grasper_2f85": pbg_robotiq_to_parallel_jaw,
           "cgn": cgn_panda_to_parallel_jaw}


# ---- the peers' finger points (their kinematics) and ours ---------------------------------------
def pbg_barrett_points(T_base, spread=PBG_SPREAD):
    """Named points of pybullet-grasper's open Barrett (finger joints at 0, spread `spread`) at its
    base-link pose: per finger its proximal joint, distal joint and fingertip (barrett_hand.urdf)."""
    T = np.asarray(T_base, dtype=float)
    chains = {
        "finger1": T @ urdf_joint(PBG_J11, spread) @ urdf_joint(PBG_J12, 0.0),
        "finger2": T @ urdf_joint(PBG_J21, spread) @ urdf_joint(PBG_J12, 0.0),
        "finger3": T @ urdf_joint(PBG_J32, 0.0),
    }
    out = {}
    for name, prox in chains.items():
        dist = prox @ urdf_joint(PBG_JDIST, 0.0)
        out[f"{name}/proximal joint"] = prox[:3, 3]
        out[f"{name}/distal joint"] = dist[:3, 3]
        out[f"{name}/fingertip"] = (dist @ np.r_[PBG_TIP, 1.0])[:3]
    return out


def bh8_points(hand, T_palm, spread=PBG_SPREAD):
    """The same named points of our `barrett_bh8` at the open preshape (hand.py's kinematics)."""
    q = hand.open_joints(spread)
    links = hand.link_poses(q, T_palm)
    names = hand.links
    tips = hand.fingertips(q, T_palm)
    out = {}
    for f in range(3):
        out[f"finger{f + 1}/proximal joint"] = links[names.index(f"finger{f + 1}/proximal")][:3, 3]
        out[f"finger{f + 1}/distal joint"] = links[names.index(f"finger{f + 1}/distal")][:3, 3]
        out[f"finger{f + 1}/fingertip"] = tips[f]
    return out


def cgn_panda_points(T_cgn):
    """Named points of Contact-GraspNet's open Panda at its pose: each finger's joint point and
    its pad at the fingertips' centre depth (cgn_driver.py docstring, mesh_utils)."""
    T = np.asarray(T_cgn, dtype=float)
    out = {}
    for side, x in (("-x finger", -CGN_HALF_OPEN), ("+x finger", CGN_HALF_OPEN)):
        out[f"{side}/joint"] = (T @ [x, 0.0, CGN_JOINT_Z, 1.0])[:3]
        out[f"{side}/pad at 0.1034"] = (T @ [x, 0.0, CGN_DEPTH, 1.0])[:3]
    return out


def parallel_jaw_points(hand, T_palm, depth=CGN_DEPTH - PJ_PALM_Z, label="pad at 0.1034"):
    """The same named points of our `parallel_jaw.urdf` at the open preshape, from our kinematics
    (hand.py: link poses and each jaw's convex mesh placed by them): the jaw links' origins (their
    joints) and the point of each jaw's pad face 0.045 m out along it (0.1034 m from pj_hand).

    The pad face is the jaw mesh's face on its link plane y = 0 (meshes/parallel_jaw_finger.obj):
    the four vertices nearest the closing mid-plane at the palm pose; the pad point is the middle of
    its base edge moved 0.045 / 0.054 of the way to the middle of its tip edge.
    """
    q = hand.open_joints()
    links = hand.link_poses(q, T_palm)
    names = hand.links
    home = {g.link: np.asarray(g.vertices) for g in hand.link_geometry(q) if g.vertices is not None}
    here = {g.link: np.asarray(g.vertices) for g in hand.link_geometry(q, T_palm) if g.vertices is not None}
    out = {}
    for jaw, side in (("left/jaw", "-x finger"), ("right/jaw", "+x finger")):
        li = names.index(jaw)
        V0, V = home[li], here[li]
        pad = np.argsort(np.abs(V0[:, 1]))[:4]             # nearest the plane y = 0 of the palm frame
        pad = pad[np.argsort(V0[pad, 2])]                   # two at the base, two at the tip
        base, tip = V[pad[:2]].mean(axis=0), V[pad[2:]].mean(axis=0)
        length = V0[pad[2:], 2].mean() - V0[pad[:2], 2].mean()
        out[f"{side}/joint"] = links[li][:3, 3]
        out[f"{side}/{label}"] = base + depth / length * (tip - base)
    return out


def pbg_robotiq_points(T_base):
    """pybullet-grasper's open 2F-85 pads at its base-link pose (-y pad, +y pad)."""
    T = np.asarray(T_base, dtype=float)
    return {f"{side} pad/middle": (T @ [0.0, y, PBG_2F85_PAD_Z, 1.0])[:3]
            for side, y in (("-y", -PBG_2F85_PAD_Y), ("+y", PBG_2F85_PAD_Y))}


def parallel_jaw_pad_middles(hand, T_palm):
    """Our open jaws' pad middles (PJ_PAD_MID out), named by the side of the palm frame they are on."""
    pts = parallel_jaw_points(hand, T_palm, depth=PJ_PAD_MID, label="pad")
    y = np.asarray(T_palm, dtype=float)[:3, 1]
    out = {}
    for name, p in pts.items():
        if name.endswith("/pad"):
            side = "+y" if (p - np.asarray(T_palm)[:3, 3]) @ y > 0 else "-y"
            out[f"{side} pad/middle"] = p
    return out


def _example_pose():
    """A tilted test pose, to catch a wrong axis that an identity pose would hide."""
    return trans(0.03, -0.02, 0.15) @ rot_axis((1, 2, 0.5), 2.2)


def check_frames(results=None, verbose=True):
    """Compares finger points of each peer's hand at its pose with ours at the converted pose.

    For each hand: an arbitrary tilted pose, plus the top grasp of each peer result given in
    `results` ({(peer, object): result dict}). Prints per point the distance (mm) and returns the
    largest distance per hand and point kind, in metres.
    """
    from bayesgrasp.hand import Hand
    bh8 = Hand.load(OUR_HAND["pybullet_grasper"])
    pj = Hand.load(OUR_HAND["cgn"])
    poses = {peer: [("tilted test pose", _example_pose())] for peer in PEER_NAMES}
    for (peer, obj), res in (results or {}).items():
        if res.get("grasps"):
            poses[peer].append((f"{obj} top-1", np.array(res["grasps"][0]["pose"])))
    worst = {}
    for peer, items in poses.items():
        for label, T in items:
            if peer == "pybullet_grasper":
                theirs, ours = pbg_barrett_points(T), bh8_points(bh8, pbg_barrett_to_bh8(T))
                title = "pybullet-grasper Barrett -> our barrett_bh8"
            elif peer == "pybullet_grasper_2f85":
                theirs, ours = pbg_robotiq_points(T), parallel_jaw_pad_middles(pj, pbg_robotiq_to_parallel_jaw(T))
                title = "pybullet-grasper Robotiq 2F-85 -> our parallel_jaw.urdf (pads 8.7 mm apart by width)"
            else:
                theirs, ours = cgn_panda_points(T), parallel_jaw_points(pj, cgn_panda_to_parallel_jaw(T))
                title = "cgn Panda -> our parallel_jaw.urdf"
            if verbose:
                print(f"check-frames: {title}, {label}")
            for name in theirs:
                d = float(np.linalg.norm(theirs[name] - ours[name]))
                kind = f"{peer}: {name.split('/')[1]}"
                worst[kind] = max(worst.get(kind, 0.0), d)
                if verbose:
                    print(f"  {name:26s} peer {np.round(theirs[name], 4)}  ours {np.round(ours[name], 4)}  "
                          f"{d * 1000:5.1f} mm")
    if verbose:
        print("check-frames: largest distance per point kind: " +
              ", ".join(f"{k} {v * 1000:.1f} mm" for k, v in worst.items()))
    return worst


# ---- running the peers --------------------------------------------------------------------------
def _run(cmd, log):
    """Runs one peer command at nice 10 from the repository root; its stderr goes to `log`."""
    t = time.perf_counter()
    with open(log, "w") as f:
        r = subprocess.run(["nice", "-n", "10", *map(str, cmd)], cwd=REPO, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        raise RuntimeError(f"{cmd[1]} failed ({r.returncode}); see {log}")
    return time.perf_counter() - t


def _mesh_arg(mesh):
    """A mesh path as the drivers get it: relative to the repository where it lies inside it."""
    mesh = Path(mesh).resolve()
    return str(mesh.relative_to(REPO)) if mesh.is_relative_to(REPO) else str(mesh)


def run_peer(peer, obj, pose, out, reuse, mesh=None, seed=0, make_cloud=None):
    """The peer's result for one object: {peer result JSON}; the request, result, partial cloud
    and log go to `out`. `mesh` defaults to OBJECTS[obj]'s. cgn's cloud comes from
    `make_cloud(path)` if given, else from make_partial_cloud.py. With `reuse`, a result already
    there for the same request is kept."""
    mesh = _mesh_arg(REPO / (mesh or OBJECTS[obj][0]))
    req = {"mesh": mesh, "pose": list(pose), "top_k": TOP_K, "seed": seed}
    cloud = out / f"cloud_{obj}.npy"
    if peer.startswith("pybullet_grasper"):
        req["hand"] = "robotiq_2f85" if peer == "pybullet_grasper_2f85" else "barrett"
        python, driver = PBG_PYTHON, PEERS / "pybullet_grasper_driver.py"
    else:
        req["hand"] = "panda"
        req["cloud"] = _mesh_arg(cloud)
        python, driver = CGN_PYTHON, PEERS / "cgn_driver.py"
    req_path, res_path = out / f"request_{peer}_{obj}.json", out / f"result_{peer}_{obj}.json"
    if reuse and res_path.exists() and req_path.exists() and json.loads(req_path.read_text()) == req:
        if peer != "cgn" or cloud.exists():
            print(f"{peer} on {obj}: reusing {res_path}")
            return json.loads(res_path.read_text())
    if peer == "cgn" and make_cloud is not None:
        make_cloud(cloud)
    elif peer == "cgn":
        _run([PBG_PYTHON, PEERS / "make_partial_cloud.py", mesh, cloud, "--pose", *pose], out / f"log_cloud_{obj}.txt")
    req_path.write_text(json.dumps(req, indent=1))
    print(f"{peer} on {obj}: running the driver ...", flush=True)
    _run([python, driver, req_path, res_path], out / f"log_{peer}_{obj}.txt")
    return json.loads(res_path.read_text())


# ---- our lift test ------------------------------------------------------------------------------
def our_world(obj, pose, hand, mesh=None, mass=None):
    """Our World with the object (OBJECTS[obj] unless `mesh` and `mass` are given) at the planar
    `pose`, the mesh's own xy origin kept; and the vertical offset the scene applied to it."""
    from bayesgrasp.objects.library import load_object
    from bayesgrasp.world import World
    if mesh is None:
        mesh, mass = OBJECTS[obj]
    model = load_object(str(REPO / mesh), mass=mass)
    world = World.single(model, pose=tuple(pose), hand=hand, keep_origin=True)
    z_shift = -float(model.bounds[0][2])   # the scene puts the mesh's lowest point on z = 0
    return world, z_shift


def our_hand_poses(peer, result, z_shift, top_k=TOP_K):
    """The peer's top-k grasps as our hand poses (N, 4, 4), table frame, moved up by `z_shift`."""
    return np.array([trans(0, 0, z_shift) @ CONVERT[peer](g["pose"]) for g in result.get("grasps", [])[:top_k]])


def judge(peer, obj, pose, result, threads=0, world=None):
    """Our lift test of the peer's top grasps: one row per rank (closed at the peer's pose, and
    as executed: `executed_lifted`), and the hand poses they were executed at. `world` (from
    :func:`our_world`, with its z_shift) defaults to OBJECTS[obj]'s at `pose`."""
    grasps = result.get("grasps", [])
    if not grasps:
        return [], np.zeros((0, 4, 4))
    world, z_shift = world or our_world(obj, pose, OUR_HAND[peer])
    H = our_hand_poses(peer, result, z_shift, top_k=len(grasps))
    spread = PBG_SPREAD if peer == "pybullet_grasper" else None
    b = world.grasp_poses(H, spread=spread, frame="world", lift=True, threads=threads)
    counts = np.diff(np.asarray(b.contacts.offsets))
    on_table = np.asarray(b.contacts.on_table, dtype=bool)
    starts = np.r_[0, np.cumsum(counts)]
    rows = []
    for i, g in enumerate(grasps):
        n_obj = int(np.count_nonzero(~on_table[starts[i]:starts[i + 1]]))
        row = {"rank": i + 1, "peer_score": g["score"], "lifted": bool(b.lifted[i]),
               "epsilon": float(b.epsilon[i]), "collision_at_start": bool(b.collision_at_start[i]),
               "object_contacts": n_obj, "lift_displacement": float(b.lift_displacement[i]),
               "our_hand_pose": H[i].tolist(), "joints": np.asarray(b.joint_angles[i]).tolist()}
        if peer.startswith("pybullet_grasper"):
            row["peer_lift_test"] = bool(g.get("lift_test"))
        else:
            row["peer_width"] = g.get("width")
        rows.append(row)
    lifted, H_exec, retries = _executed(world, H, b, spread)
    for row, ok, retry in zip(rows, lifted, retries):
        if retry is not None:
            row["approach_retry"] = {k: v for k, v in retry.items() if k != "hand_pose"}
        row["executed_lifted"] = bool(ok)
    return rows, H_exec


def _executed(world, H, b, spread):
    """The grasps at hand poses H (N, 4, 4, world), closed at them in the batch `b`, executed as a
    robot would: as closed where the pose is free; where the open hand would start in collision,
    moved in from RETRY_BACKOFF behind until its first contact (approach_retry). Returns (lifted
    per grasp, the poses the hand closed at, per grasp its retry or None)."""
    H_exec = np.array(H, dtype=float)
    lifted = np.asarray(b.lifted, dtype=bool).copy()
    retries = [None] * len(H)
    for i in np.flatnonzero(np.asarray(b.collision_at_start, dtype=bool)):
        retries[i] = approach_retry(world, H[i], spread, keep_pose=True)
        lifted[i] = retries[i]["lifted"]
        if "hand_pose" in retries[i]:
            H_exec[i] = retries[i]["hand_pose"]
    return lifted, H_exec, retries


def execute(world, H, spread, threads=0):
    """Lifted per grasp for hand poses H (N, 4, 4, world) executed as a robot would (_executed)."""
    b = world.grasp_poses(H, spread=spread, frame="world", lift=True, threads=threads)
    return _executed(world, H, b, spread)[0]


RETRY_BACKOFF = 0.1   # m: pybullet-grasper's own approach (forward_joint's 0.1 m move before closing)


def approach_retry(world, H, spread, keep_pose=False):
    """A second try of a grasp whose hand starts in collision at the peer's pose: our open hand
    starts RETRY_BACKOFF behind it along its approach (for pybullet-grasper exactly the peer's
    pose before its 0.1 m forward move, converted), moves along +z until its first contact with
    the object or the table (World.approach, no stand-off), closes and is lift-tested. The peer's
    own hand does the like: its forward move stops where it meets the object."""
    from bayesgrasp.hand import Hand
    pre = H @ trans(0.0, 0.0, -RETRY_BACKOFF)
    d = pre[:3, 2]
    try:
        g = world.approach(d, pre[:3, 3], roll=Hand.approach_roll(pre), spread=spread, standoff=0.0,
                           frame="world", lift=True)
    except ValueError as e:   # e.g. the start point lies below the table: no second try
        return {"lifted": False, "error": str(e)}
    travel = float((np.asarray(g.hand_pose)[:3, 3] - pre[:3, 3]) @ d)
    turn = float(np.degrees(np.arccos(np.clip((np.trace(np.asarray(g.hand_pose)[:3, :3].T @ pre[:3, :3]) - 1) / 2,
                                              -1, 1))))
    out = {"lifted": bool(g.lifted), "epsilon": float(g.epsilon), "collision_at_start": bool(g.collision_at_start),
           "travel": travel, "orientation_error_deg": turn,
           "object_contacts": sum(1 for c in g.contacts if not c.on_table)}
    if keep_pose and not g.collision_at_start:
        out["hand_pose"] = np.asarray(g.hand_pose)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", nargs="+", default=list(OBJECTS), choices=list(OBJECTS))
    ap.add_argument("--pose", nargs=3, type=float, default=[0.0, 0.0, 0.0], metavar=("X", "Y", "YAW"))
    ap.add_argument("--peers", nargs="+", default=["pybullet_grasper", "cgn"], choices=list(PEER_NAMES))
    ap.add_argument("--out", type=Path, default=OUT_DEFAULT)
    ap.add_argument("--reuse", action="store_true", help="keep peer results already in --out for the same request")
    ap.add_argument("--check-frames", action="store_true", help="only compare the hands' finger points")
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args(argv)

    if args.check_frames:
        found = {}
        for peer in PEER_NAMES:
            for obj in OBJECTS:
                p = args.out / f"result_{peer}_{obj}.json"
                if p.exists():
                    found[(peer, obj)] = json.loads(p.read_text())
        check_frames(found)
        return

    args.out.mkdir(parents=True, exist_ok=True)
    pose = [float(v) for v in args.pose]
    results, report = {}, {"pose": pose, "objects": {}, "our_hands": OUR_HAND,
                           "conversions": {"pybullet_grasper": f"ours = peer base @ Trans(0, 0, {PBG_PALM_FACE_Z})",
                                           "cgn": f"ours = peer @ Trans(0, 0, {PJ_PALM_Z}) @ Rz(90 deg)"}}
    for obj in args.objects:
        for peer in args.peers:
            results[(peer, obj)] = run_peer(peer, obj, pose, args.out, args.reuse)
    worst = check_frames(results)
    report["check_frames_max_mm"] = {k: round(v * 1000, 2) for k, v in worst.items()}

    for obj in args.objects:
        report["objects"][obj] = {}
        for peer in args.peers:
            res = results[(peer, obj)]
            t = time.perf_counter()
            rows, _ = judge(peer, obj, pose, res, threads=args.threads)
            entry = {"peer_seconds": res.get("seconds"), "peer_counts": res.get("counts"),
                     "judge_seconds": time.perf_counter() - t, "grasps": rows,
                     "top1_lifted": bool(rows and rows[0]["lifted"]),
                     "top5_lifted": any(r["lifted"] for r in rows[:TOP_K]),
                     "top5_lifted_with_retries": any(r["lifted"] or r.get("approach_retry", {}).get("lifted", False)
                                                     for r in rows[:TOP_K])}
            if peer.startswith("pybullet_grasper"):
                entry["peer_top1_held"] = bool(rows and rows[0]["peer_lift_test"])
                entry["peer_top5_held"] = any(r["peer_lift_test"] for r in rows[:TOP_K])
                entry["note"] = ("top 5 by the peer's score among its tested candidates; "
                                 f"{(res.get('counts') or {}).get('lift_ok', '?')} of them held in its own test")
            else:
                entry["peer_seconds_inference"] = res.get("seconds_inference")
            report["objects"][obj][peer] = entry
    (args.out / "judge.json").write_text(json.dumps(report, indent=1))

    print()
    print(f"{'object':22s} {'peer':17s} {'ours: top-1':>11s} {'top-5':>6s} {'top-5 w/ retry':>14s}  "
          f"{'peer test: top-1':>16s} {'top-5':>6s}  {'peer s':>7s}")
    yn = {True: "yes", False: "no"}
    for obj, per in report["objects"].items():
        for peer, e in per.items():
            own1 = yn[e["peer_top1_held"]] if "peer_top1_held" in e else "-"
            own5 = yn[e["peer_top5_held"]] if "peer_top5_held" in e else "-"
            print(f"{obj:22s} {peer:17s} {yn[e['top1_lifted']]:>11s} {yn[e['top5_lifted']]:>6s} "
                  f"{yn[e['top5_lifted_with_retries']]:>14s}  {own1:>16s} "
                  f"{own5:>6s}  {e['peer_seconds']:7.1f}")
    print()
    for obj, per in report["objects"].items():
        for peer, e in per.items():
            print(f"{obj} {peer}: " + "; ".join(
                f"#{r['rank']} score {r['peer_score']:.3f} lifted {yn[r['lifted']]} eps {r['epsilon']:.3f}"
                f"{' START-COLLISION' if r['collision_at_start'] else ''} contacts {r['object_contacts']}"
                + (f" peer-held {yn[r['peer_lift_test']]}" if 'peer_lift_test' in r else "")
                + (f" [retry from {RETRY_BACKOFF} m back: moved {r['approach_retry']['travel']:.3f} m, "
                   f"lifted {yn[r['approach_retry']['lifted']]}"
                   f"{', starts in collision' if r['approach_retry']['collision_at_start'] else ''}]"
                   if 'travel' in r.get('approach_retry', {}) else
                   f" [no retry: {r['approach_retry']['error']}]" if 'approach_retry' in r else "")
                for r in e["grasps"]))
    print()
    for obj, per in report["objects"].items():
        for peer, e in per.items():
            c = e["peer_counts"] or {}
            extra = (f"{e['peer_seconds_inference']:.1f} s of it inference" if peer == "cgn" else
                     f"{c.get('candidates')} candidates, {c.get('tested')} tested, {c.get('lift_ok')} held in its test")
            print(f"time: {obj} {peer}: {e['peer_seconds']:.1f} s wall ({extra}); our judging {e['judge_seconds']:.1f} s")
    print(f"\nwrote {(args.out / 'judge.json')}")


if __name__ == "__main__":
    main()
