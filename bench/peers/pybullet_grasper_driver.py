"""Driver for the peer planner pybullet-grasper 0.0.2 (Rustler & Hoffmann, CC BY 4.0).

Run by the python of its own virtual environment (`.venv-peer-pbg`, see README.md here):

    .venv-peer-pbg/bin/python bench/peers/pybullet_grasper_driver.py REQUEST.json RESULT.json

Request (JSON): {"mesh": OBJ/STL in metres, object frame z up resting on z = 0,
                 "pose": [x, y, yaw] of the object on the table, "hand": "barrett" | "robotiq_2f85",
                 "top_k": 5, "seed": 0, optional "workers": simulation processes (default: all cores)}
Result (JSON):  {"planner", "version", "hand", "grasps": [{"pose", "pose_peer", "score", "joints",
                 "lift_test"}], "seconds", "peer_lift_test", "counts", "patches"}

What the peer does (read from its installed source): it samples 250-500 points on the object's
surface (Open3D, uniform), and for each point tries up to three hand orientations about the inward
normal (0, 90, 180 degrees) and three stand-offs until the hand is collision-free; then, in
`cpu_count() - 2` forked PyBullet processes, it places the hand, moves it 0.1 m forward along its
approach axis, closes the fingers until a contact torque stops them, drops the support plane by
0.2 m (the "lift"), turns the hand by +90, -90 and 0 degrees about its approach axis (the "shake"),
waits one simulated second and scores the grasp. Each test has a 2 s wall-clock alarm; a test that
hits it, or whose hand starts in collision, keeps the score -1.

Frame conventions of the peer's hand pose (all in the peer's world frame, which this driver makes
equal to our table frame, z up, table top at z = 0):

* The pose it returns (`pose_peer` here, position + quaternion x, y, z, w in its response) is the
  pose of the hand URDF's root link ("world") before the approach. Its +z axis is the approach
  direction: it points into the object, along the inward surface normal of the sampled point.
  The root sits 0.2-0.22 m out along the outward normal from that surface point (0.1-0.12 m
  stand-off plus 0.1 m added because `move_to_grasp_pose` is on).
* Between the root and the hand's base link are a revolute joint about z (`rotation_joint`, the
  shake) and a prismatic joint along z (`forward_joint`). Before closing, `forward_joint` moves the
  hand 0.1 m along +z. `pose` in our result is therefore `pose_peer @ Trans(0, 0, 0.1)`: the hand's
  base link at the moment of closing (nominal; a collision on the way may stop it short).
* Barrett hand (base link `bh_base_link`): origin at the wrist side of the palm housing, centre of
  the palm; the palm face is at z = +0.079 m (palm_280.obj within 30 mm of the centre; 0.090 m is the top of finger 3's housing). Finger 3 (the thumb, joints bh_j32/bh_j33) is at
  y = -0.05 m, fingers 1 and 2 (bh_j12/bh_j13, bh_j22/bh_j23) at x = +/-0.025 m, y = +0.05 m; at zero
  joint angles the fingers lie flat along -y and +y and curl towards +z as their joints grow
  (0 to 2.44 rad, distal joint coupled at 0.344 of the proximal one). The spread bh_j11 (coupled
  to bh_j21) is held at 0.01 rad: fingers 1 and 2 oppose the thumb, so the hand closes along y.
* Robotiq 2F-85 (base link `robotiq_arg2f_85_base_link`): origin at the coupling face of the base,
  axis z out through the fingers; the finger pads (`left_contactile`, `right_contactile`) are at
  z = 0.150 m, y = -/+0.0487 m when open (finger_joint = 0); the jaws close along y. The peer
  commands finger_joint = 0.005 + 0.685 s + 0.103 s^2 for an opening s in [0, 1] (1 = closed).

Patches applied from here (the installed package is never edited):
1. `pybullet_grasper.grasp_generator.mp` is replaced by a view of `multiprocessing` whose
   `cpu_count()` returns workers + 2, so that `cpu_count() - 2` worker processes is `workers`
   (unpatched, on 2 cores it starts 0 processes and silently returns no grasp).
2. `ClientProcess.__init__`, `ClientProcess.test_grasp` and the hands' `stop()` are wrapped to record,
   per candidate, the finger joint angles at the end of closing, whether the object is still in
   contact with the hand after the lift and shake (the peer's own `stable_grasp`, taken from the
   same PyBullet state right after its test returns), how the closing ended (`counts.closing`:
   not closed = rejected before closing by the peer's collision checks, closed empty = the fingers
   met nothing and the peer drops the candidate) and whether the 2 s alarm fired.
3. The peer reads meshes from a folder named `objects/` and writes URDFs to the sibling `urdf/`
   folder (by string replacement in the path); this driver builds that layout in a temp dir.
"""
import json
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
import types

import numpy as np

PLANNER = "pybullet-grasper"
VERSION = "0.0.2"
APPROACH_ADVANCE = 0.1   # forward_joint target before closing (move_to_grasp_pose: True)
PEER_HAND = {"barrett": "barrett", "robotiq_2f85": "robotiq"}

# The peer's default.yaml with the interactive parts turned off.
CONFIG_YAML = """gripper: "{gripper}"
debug: False
visualization:
  resolution: [640, 480]
  debug_sleep: 0.0
  show_last: False
contacts:
  time_step: 480
  detection_method: "force"
  contact_threshold: 5
  move_to_grasp_pose: True
analytical:
  enabled: False
  cone_vertices: 8
  force_threshold: 0
  gws:
    merging_radius: 1e-4
    scale: True
    scale_interval: [-0.5, 0.5]
"""


def pose_matrix(position, quat_xyzw):
    """4x4 homogeneous matrix of a position and a unit quaternion (x, y, z, w)."""
    x, y, z, w = quat_xyzw
    rot = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = position
    return out


def table_transform(pose):
    """Object-to-table transform of a planar pose [x, y, yaw]."""
    x, y, yaw = (float(v) for v in pose)
    out = np.eye(4)
    c, s = np.cos(yaw), np.sin(yaw)
    out[:2, :2] = [[c, -s], [s, c]]
    out[:2, 3] = [x, y]
    return out


def build_layout(mesh_path, pose, hand, workdir):
    """objects/object.obj (the mesh placed on the table) and an empty urdf/ beside it, plus the config."""
    import open3d as o3d
    mesh = o3d.io.read_triangle_mesh(mesh_path)
    if len(mesh.triangles) == 0:
        raise ValueError(f"mesh: no triangles read from {mesh_path}")
    mesh.transform(table_transform(pose))
    os.makedirs(os.path.join(workdir, "objects"))
    os.makedirs(os.path.join(workdir, "urdf"))
    obj_path = os.path.join(workdir, "objects", "object.obj")
    o3d.io.write_triangle_mesh(obj_path, mesh, write_vertex_normals=False, write_vertex_colors=False)
    cfg_path = os.path.join(workdir, "config.yaml")
    with open(cfg_path, "w") as f:
        f.write(CONFIG_YAML.format(gripper=PEER_HAND[hand]))
    return obj_path, cfg_path


class Recorder:
    """Shared per-candidate records filled in by the peer's worker processes (patch 2)."""
    processes = []     # ClientProcess objects in creation order (parent process)
    current = None     # (process, pose index) under test (worker process)
    joint_ids = []     # movable finger joints of the hand, in PyBullet order
    joint_names = []


def install_patches(workers):
    from pybullet_grasper import grasp_generator as gg
    from pybullet_grasper import bullet_classes as bc

    # Patch 1: the worker count.
    mp_view = types.SimpleNamespace(**{k: getattr(multiprocessing, k) for k in dir(multiprocessing)
                                       if not k.startswith("__")})
    mp_view.cpu_count = lambda: workers + 2
    gg.mp = mp_view

    # Patch 2: records of each candidate.
    original_init = gg.ClientProcess.__init__
    original_test = gg.ClientProcess.test_grasp

    def init(self, client, id, gripper_poses, score, after_grasp_poses):
        original_init(self, client, id, gripper_poses, score, after_grasp_poses)
        n = len(gripper_poses)
        self.bg_joints = multiprocessing.Array("d", n * max(1, len(Recorder.joint_ids)))
        self.bg_lift = multiprocessing.Array("b", n)
        self.bg_timeout = multiprocessing.Array("b", n)
        self.bg_close = multiprocessing.Array("b", n)   # closing result: 0 not closed, 1 empty, 2 contact, 3 timeout
        Recorder.processes.append(self)

    def test_grasp(self, gripper_pose, pose_id):
        Recorder.current = (self, pose_id)
        try:
            ret = original_test(self, gripper_pose, pose_id)
        except TimeoutError:
            self.bg_timeout[pose_id] = 1
            raise
        finally:
            Recorder.current = None
        if self.score[pose_id] != -1:
            client = self.client
            contacts = client.getContactPoints(client.gripper.id, client.object.id)
            self.bg_lift[pose_id] = 1 if len(contacts) > 0 else 0
        return ret

    gg.ClientProcess.__init__ = init
    gg.ClientProcess.test_grasp = test_grasp

    for hand_cls in (bc.Barrett, bc.Robotiq_2f_85):
        original_stop = hand_cls.stop

        def stop(self, _original=original_stop):
            _original(self)
            if Recorder.current is not None:
                proc, pose_id = Recorder.current
                k = len(Recorder.joint_ids)
                for i, j in enumerate(Recorder.joint_ids):
                    proc.bg_joints[pose_id * k + i] = self.client.getJointState(self.id, j)[0]

        hand_cls.stop = stop
        original_set = hand_cls.set_gripper_pose

        def set_gripper_pose(self, position, *args, _original=original_set, **kwargs):
            ret = _original(self, position, *args, **kwargs)
            if kwargs.get("wait") and Recorder.current is not None:
                proc, pose_id = Recorder.current
                proc.bg_close[pose_id] = int(ret)
            return ret

        hand_cls.set_gripper_pose = set_gripper_pose


def finger_joints(client, body):
    """Revolute joints of the hand other than the shake joint (index 0), PyBullet order."""
    ids, names = [], []
    for j in range(client.getNumJoints(body)):
        info = client.getJointInfo(body, j)
        name = info[1].decode()
        if info[2] == client.JOINT_REVOLUTE and name != "rotation_joint":
            ids.append(j)
            names.append(name)
    return ids, names


def collect(top_k):
    rows = []
    k = len(Recorder.joint_ids)
    for proc in Recorder.processes:
        for i, pose in enumerate(proc.gripper_poses):
            score = float(proc.score[i])
            pos = [pose.position.x, pose.position.y, pose.position.z]
            quat = [pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w]
            peer = pose_matrix(pos, quat)
            advance = np.eye(4)
            advance[2, 3] = APPROACH_ADVANCE
            rows.append({
                "pose": (peer @ advance).tolist(),
                "pose_peer": peer.tolist(),
                "score": score,
                "joints": {n: float(proc.bg_joints[i * k + m]) for m, n in enumerate(Recorder.joint_names)},
                "lift_test": bool(proc.bg_lift[i]),
                "timed_out": bool(proc.bg_timeout[i]),
                "close": int(proc.bg_close[i]),
            })
    tested = [r for r in rows if r["score"] != -1]
    counts = {"candidates": len(rows), "tested": len(tested),
              "lift_ok": sum(r["lift_test"] for r in tested),
              "timed_out": sum(r["timed_out"] for r in rows),
              "closing": {name: sum(r["close"] == code for r in rows) for code, name in
                          ((0, "not_closed"), (1, "closed_empty"), (2, "contact"), (3, "close_timeout"))}}
    tested.sort(key=lambda r: -r["score"])
    best = tested[:top_k]
    for r in best:
        del r["timed_out"], r["close"]
    return best, counts


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: pybullet_grasper_driver.py REQUEST.json RESULT.json")
    with open(argv[1]) as f:
        req = json.load(f)
    hand = req.get("hand", "barrett")
    if hand not in PEER_HAND:
        raise ValueError(f"hand: expected one of {sorted(PEER_HAND)}, got {hand!r}")
    top_k = int(req.get("top_k", 5))
    seed = int(req.get("seed", 0))
    workers = int(req.get("workers", os.cpu_count() or 1))

    start = time.perf_counter()
    import open3d as o3d
    np.random.seed(seed)                 # the peer shuffles the candidates with numpy's global RNG
    o3d.utility.random.seed(seed)        # and samples the surface with Open3D's
    install_patches(workers)
    from pybullet_grasper.grasp_generator import GraspGenerator

    workdir = tempfile.mkdtemp(prefix="bg_pbg_")
    try:
        obj_path, cfg_path = build_layout(req["mesh"], req.get("pose", [0, 0, 0]), hand, workdir)
        gen = GraspGenerator(obj_path, init_position=[0, 0, 0], config_name=cfg_path, ros=False)
        Recorder.joint_ids, Recorder.joint_names = finger_joints(gen.client, gen.client.gripper.id)
        print(f"pybullet-grasper: {gen.num_poses} candidates, {workers} workers", file=sys.stderr)
        gen.run()
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    grasps, counts = collect(top_k)
    seconds = time.perf_counter() - start

    result = {
        "planner": PLANNER, "version": VERSION, "hand": hand,
        "frame": "table (z up, table top z = 0); pose = hand base link at closing, +z approach",
        "grasps": grasps, "seconds": seconds,
        "peer_lift_test": [g["lift_test"] for g in grasps],
        "counts": counts, "workers": workers, "seed": seed,
        "patches": ["grasp_generator.mp.cpu_count -> workers + 2",
                    "ClientProcess/hand.stop wrapped to record joints, lift result, timeouts",
                    "objects/ + urdf/ layout in a temp dir"],
    }
    with open(argv[2], "w") as f:
        json.dump(result, f, indent=1)
    print(f"pybullet-grasper: {counts['tested']}/{counts['candidates']} tested, "
          f"{counts['lift_ok']} held after lift+shake, {counts['timed_out']} hit the 2 s alarm, "
          f"{seconds:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv)
