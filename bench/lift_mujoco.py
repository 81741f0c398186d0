"""Replays exported grasps (bench/lift_heldset.py) in MuJoCo: an independent check of our lift test.

The same scene in MuJoCo (PyPI ``mujoco``, needs only numpy besides): the palm and knuckles a
mocap body at the hand pose (the spread frozen), every phalanx a body on a hinge at its joint
(capsules and boxes as the hand file gives them, 80 g, the same inertia), the object a free
body with our mesh's mass, centre of mass and inertia, its collision shape the convex hull or
the convex pieces our lift test used for that grasp, the table a plane; friction mu on the
hand and table_mu on the table (geom priority), condim 3, elliptic cones.
The squeeze model as in cpp/bayesgrasp/physics/squeeze_model.hpp: one velocity-servo motor
per finger (target closing_speed) on its driven phalanx, at most that joint's torque from the
hand file (each phalanx's torque_nm; ``--finger-torque T`` > 0: T at every joint), the later
phalanges coupled by joint equalities (q_j = c + ratio_j / ratio_a q_a), breakaway when the
driven phalanx touches the object and has stalled for 10 ms or reaches its limit (equality
off, the phalanx locked by its range), the worm lock as a ratchet with a backlash: a driven
joint's lower limit max(hand lower, largest angle reached - 0.01 rad), a locked phalanx held in
[largest reached - 0.01 rad, largest reached], a coupled one within the hand file's limits (held
by the equality). Each phalanx has the drive's reflected inertia, 1e-3 kg m^2 about its joint
(the joint's armature).
Script: squeeze 0.15 s, lift 10 cm in 0.4 s (cosine), 3-axis shake 1 cm 3 Hz 0.5 s, hold 0.1 s;
verdict (lift_test.hpp): lifted = finite, the object's centre of mass rose >= 10 - 2 cm in the
world (height_gain, end minus start), and moved < 2 cm in the palm frame from the end of the
lift to the end (hold_displacement). Stopped early when lost: lagging the palm's rise by more
than 5 cm, or moved more than 5 cm in the palm frame after the lift. ``displacement`` (end vs
after the squeeze, palm frame) is reported for diagnosis.
Prints the verdict agreement with ours and writes per-grasp rows (JSON) for the report.

    .venv-mj/bin/python bench/lift_mujoco.py bench/results/heldset --out bench/results/lift_mujoco.json
"""
import argparse
import glob
import json
import os
import sys
import time

import numpy as np
import mujoco

SQUEEZE, LIFT, SHAKE, HOLD = 0.15, 0.40, 0.5, 0.1
LIFT_H, SHAKE_A, SHAKE_F = 0.10, 0.01, 3.0
SUCCESS = 0.02
LOST = max(0.05, 2.5 * SUCCESS)
SPEED, LINK_MASS = 1.0, 0.08
#: The solref time constant (s) of the hand's and the object's geoms; None: MuJoCo's default (0.02 s,
#: soft: a fingertip pressed with tens of newtons sinks millimetres in). Set by --contact-solref.
CONTACT_SOLREF = None
BACKLASH, DRIVE_INERTIA = 0.01, 1e-3  # rad (the worm's), kg m^2 (the drive's, as the joint's armature)
STALL_FRACTION, STALL_TIME = 0.1, 0.01


def joint_torques(hand, finger_torque=0.0):
    """Per finger, per phalanx: the motor's torque limit at that joint (N m): finger_torque if > 0,
    else the hand file's torque_nm (squeeze_model.cpp)."""
    if finger_torque and finger_torque > 0:
        return [[float(finger_torque)] * len(fi["phalanges"]) for fi in hand["fingers"]]
    out = []
    for fi in hand["fingers"]:
        row = []
        for ph in fi["phalanges"]:
            if ph.get("torque_nm") is None:
                raise ValueError(f"hand file: no torque_nm for {fi['name']}/{ph['name']}; pass --finger-torque")
            row.append(float(ph["torque_nm"]))
        out.append(row)
    return out


def palm_offset(t):
    d = np.zeros(3)
    t -= SQUEEZE
    if t <= 0:
        return d
    d[2] = LIFT_H * 0.5 * (1 - np.cos(np.pi * min(1.0, t / LIFT)))
    t -= LIFT
    if 0 < t < SHAKE:
        env = np.sin(np.pi * t / SHAKE) ** 2
        w = 2 * np.pi * SHAKE_F * t
        d += SHAKE_A * env * np.sin(w + 2 * np.pi * np.arange(3) / 3)
    return d


def mass_properties(V, F):
    """Mass-free volume, centre and second moments of a closed mesh (signed tetrahedra)."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    vol6 = np.einsum("ij,ij->i", a, np.cross(b, c))
    vol = vol6.sum() / 6
    com = ((a + b + c) * vol6[:, None]).sum(0) / (24 * vol)
    # Covariance of each tetrahedron (0, a, b, c) about the origin: vol6/120 (sum x x^T + (sum x)(sum x)^T).
    s = a + b + c
    C = (np.einsum("i,ij,ik->jk", vol6, a, a) + np.einsum("i,ij,ik->jk", vol6, b, b) +
         np.einsum("i,ij,ik->jk", vol6, c, c) + np.einsum("i,ij,ik->jk", vol6, s, s)) / 120
    C -= vol * np.outer(com, com)
    return vol, com, np.trace(C) * np.eye(3) - C  # inertia per unit density about the centre


def quat(R):
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).reshape(-1))
    return q


def fmt(v):
    return " ".join(f"{x:.9g}" for x in np.ravel(v))


def shape_geoms(rows, T, cls):
    """MJCF geoms for one link's shapes (rows of link_shapes), placed by T (link -> body frame)."""
    out = []
    for r in rows:
        kind, center, half, p0, p1, rad = int(r[1]), r[2:5], r[5:8], r[8:11], r[11:14], r[14]
        if kind == 1:
            a, b = T[:3, :3] @ p0 + T[:3, 3], T[:3, :3] @ p1 + T[:3, 3]
            out.append(f'<geom class="{cls}" type="capsule" fromto="{fmt(a)} {fmt(b)}" size="{rad:.9g}"/>')
        else:
            c = T[:3, :3] @ center + T[:3, 3]
            out.append(f'<geom class="{cls}" type="box" pos="{fmt(c)}" quat="{fmt(quat(T[:3, :3]))}" size="{fmt(half)}"/>')
    return out


def build(z, g, hand, timestep, finger_torque=0.0):
    """The MJCF of grasp g of the exported object z; returns (xml, meta)."""
    torques = joint_torques(hand, finger_torque)
    V, F = z["V"], z["F"]
    link_poses, q0 = z["link_poses"][g], z["joints"][g]
    shapes, fingers = z["link_shapes"], z["finger_links"]
    mu, table_mu = float(z["mu"]), 0.5
    mass = float(z["mass"])
    vol, com, I1 = mass_properties(V, F)
    inertia = I1 * mass / vol
    use_pieces = str(z["shape"][g]) == "decomposition"
    meshes = [z[f"piece_{i}"] for i in range(int(z["num_pieces"]))] if use_pieces else [V]
    assets = "\n".join(f'<mesh name="m{i}" vertex="{fmt(m)}"/>' for i, m in enumerate(meshes))
    obj_geoms = "\n".join(f'<geom class="obj" type="mesh" mesh="m{i}"/>' for i in range(len(meshes)))
    P = z["hand_pose"][g]
    Pinv = np.linalg.inv(P)
    by_link = {}
    for r in shapes:
        by_link.setdefault(int(r[0]), []).append(r)
    phal = {int(l) for f in fingers for l in f}
    palm_geoms = []
    for li in range(len(link_poses)):
        if li in phal:
            continue
        palm_geoms += shape_geoms(by_link.get(li, []), Pinv @ link_poses[li], "hand")
    joint_of = {}
    torque_of = {}
    jf = hand["fingers"]
    k = 1
    for f, links in enumerate(fingers):
        for j, l in enumerate(links):
            joint_of[int(l)] = k
            torque_of[k] = torques[f][j]
            k += 1

    def chain(f, j, parent_T):
        l = int(fingers[f][j])
        T = link_poses[l]
        rel = np.linalg.inv(parent_T) @ T
        kq = joint_of[l]
        ph = jf[f]["phalanges"][j]
        lo, hi = np.radians(ph["lower_deg"]) - q0[kq], np.radians(ph["upper_deg"]) - q0[kq]
        L = max(ph["length"], 0.01)
        inner = chain(f, j + 1, T) if j + 1 < len(fingers[f]) else ""
        return (f'<body name="l{l}" pos="{fmt(rel[:3, 3])}" quat="{fmt(quat(rel[:3, :3]))}">'
                f'<inertial pos="0 0 0" mass="{LINK_MASS}" diaginertia="{fmt([LINK_MASS * 1e-4, LINK_MASS * L * L / 3, LINK_MASS * L * L / 3])}"/>'
                f'<joint name="j{kq}" type="hinge" axis="0 1 0" limited="true" range="{min(lo, 0):.9g} {max(hi, 1e-6):.9g}" damping="0" armature="{DRIVE_INERTIA:.9g}"/>'
                + "".join(shape_geoms(by_link.get(l, []), np.eye(4), "hand")) + inner + "</body>")

    fingers_xml = "".join(chain(f, 0, P) for f in range(len(fingers)))
    acts = "".join(f'<velocity name="a{kq}" joint="j{kq}" kv="1" forcelimited="true" forcerange="{-torque_of[kq]:.9g} {torque_of[kq]:.9g}"/>'
                   for kq in range(1, k))
    eqs = []
    for f, links in enumerate(fingers):
        for j in range(1, len(links)):
            for a in range(j):
                eqs.append(f'<joint name="e{f}_{j}_{a}" joint1="j{joint_of[int(links[j])]}" '
                           f'joint2="j{joint_of[int(links[a])]}" polycoef="0 1 0 0 0" active="false"/>')
    solref = "" if CONTACT_SOLREF is None else f' solref="{CONTACT_SOLREF:.9g} 1"'
    xml = f"""<mujoco>
<compiler angle="radian"/>
<option timestep="{timestep}" gravity="0 0 -9.81" cone="elliptic" impratio="10" integrator="implicitfast"/>
<default>
  <joint solreflimit="{2 * timestep} 1" solimplimit="0.99 0.999 0.0001"/>
  <equality solref="{2 * timestep} 1" solimp="0.99 0.999 0.0001"/>
  <default class="obj"><geom contype="1" conaffinity="6" condim="3" friction="{mu} 0.005 0.0001" priority="0"{solref}/></default>
  <default class="hand"><geom contype="2" conaffinity="0" condim="3" friction="{mu} 0.005 0.0001" priority="1"{solref}/></default>
</default>
<asset>{assets}</asset>
<worldbody>
  <geom name="table" type="plane" size="2 2 0.1" contype="4" conaffinity="0" condim="3" friction="{table_mu} 0.005 0.0001" priority="1"/>
  <body name="object" pos="0 0 0">
    <freejoint/>
    <inertial pos="{fmt(com)}" mass="{mass:.9g}" fullinertia="{fmt(inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]])}"/>
    {obj_geoms}
  </body>
  <body name="palm" pos="{fmt(P[:3, 3])}" quat="{fmt(quat(P[:3, :3]))}" gravcomp="1">
    <inertial pos="0 0 0" mass="1000" diaginertia="100 100 100"/>
    <joint name="px" type="slide" axis="{fmt(P[0, :3])}"/><joint name="py" type="slide" axis="{fmt(P[1, :3])}"/><joint name="pz" type="slide" axis="{fmt(P[2, :3])}"/>
    {"".join(palm_geoms)}
    {fingers_xml}
  </body>
</worldbody>
<actuator>{acts}</actuator>
<equality>{"".join(eqs)}</equality>
</mujoco>"""
    return xml, dict(joint_of=joint_of, njoints=k, torque_of=torque_of)


def replay(z, g, hand, timestep, verbose=False, finger_torque=0.0):
    """MuJoCo's lift test of grasp g: lifted, displacement, hold_displacement, height_gain, finite,
    breakaway (finger_torque > 0: every motor's limit; 0: the hand file's)."""
    xml, meta = build(z, g, hand, timestep, finger_torque)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    fingers = z["finger_links"]
    q0 = z["joints"][g]
    jf = hand["fingers"]
    nf = len(fingers)
    jid = {kq: m.joint(f"j{kq}").id for kq in range(1, meta["njoints"])}
    qadr = {kq: m.jnt_qposadr[jid[kq]] for kq in jid}
    vadr = {kq: m.jnt_dofadr[jid[kq]] for kq in jid}
    aid = {kq: m.actuator(f"a{kq}").id for kq in jid}
    body_link = {m.body(f"l{int(l)}").id: int(l) for f in fingers for l in f}
    geom_link = np.array([body_link.get(int(b), -1) for b in m.geom_bodyid])
    obj_body = m.body("object").id
    obj_geom = m.geom_bodyid == obj_body
    kj = [[meta["joint_of"][int(l)] for l in fingers[f]] for f in range(nf)]
    ratio = [[jf[f]["phalanges"][j]["ratio"] for j in range(len(kj[f]))] for f in range(nf)]
    offset = [[np.radians(jf[f]["phalanges"][j]["offset_deg"]) for j in range(len(kj[f]))] for f in range(nf)]
    lower = [[np.radians(jf[f]["phalanges"][j]["lower_deg"]) for j in range(len(kj[f]))] for f in range(nf)]
    upper = [[np.radians(jf[f]["phalanges"][j]["upper_deg"]) for j in range(len(kj[f]))] for f in range(nf)]
    # The closed grasp's breakaway state (squeeze_model.cpp).
    driven = []
    for f in range(nf):
        a = 0
        while a + 1 < len(kj[f]):
            t = (q0[kj[f][a]] - offset[f][a]) / ratio[f][a]
            beyond = q0[kj[f][a]] >= upper[f][a] - 1e-4
            for j in range(a + 1, len(kj[f])):
                law = np.clip(offset[f][j] + ratio[f][j] * t, lower[f][j], upper[f][j])
                beyond = beyond or q0[kj[f][j]] > law + 1e-3
            if not beyond:
                break
            a += 1
        driven.append(a)
    reached = {kq: 0.0 for kq in jid}  # the worm lock (relative to the closed angles)
    base = {kq: m.jnt_range[jid[kq]].copy() for kq in jid}  # the hand file's limits (relative)
    phalanx = {kq: (f, j) for f in range(nf) for j, kq in enumerate(kj[f])}
    stall = [0] * nf
    stall_steps = max(1, int(np.ceil(STALL_TIME / timestep - 1e-9)))

    def set_drive(f):
        a = driven[f]
        for j, kq in enumerate(kj[f]):
            on = j == a
            m.actuator_gainprm[aid[kq], 0] = 1e3 if on else 0.0
            m.actuator_biasprm[aid[kq], 2] = -1e3 if on else 0.0
            d.ctrl[aid[kq]] = SPEED if on else 0.0
        for j in range(1, len(kj[f])):
            for b in range(j):
                e = m.equality(f"e{f}_{j}_{b}").id
                on = b == a and j > a
                if on:  # q_j = c + (ratio_j / ratio_a) q_a from here
                    gr = ratio[f][j] / ratio[f][a]
                    m.eq_data[e, :5] = [d.qpos[qadr[kj[f][j]]] - gr * d.qpos[qadr[kj[f][a]]], gr, 0, 0, 0]
                d.eq_active[e] = on

    for f in range(nf):
        set_drive(f)
    steps = int(np.ceil((SQUEEZE + LIFT + SHAKE + HOLD) / timestep - 1e-9))
    sq_steps = int(np.ceil(SQUEEZE / timestep - 1e-9))
    lift_steps = int(np.ceil((SQUEEZE + LIFT) / timestep - 1e-9))
    P = z["hand_pose"][g]
    R, p0 = P[:3, :3], P[:3, 3].copy()
    rel = lambda pp: R.T @ (d.xipos[obj_body] - pp)
    palm_q = [m.jnt_qposadr[m.joint(n).id] for n in ("px", "py", "pz")]
    palm_v = [m.jnt_dofadr[m.joint(n).id] for n in ("px", "py", "pz")]
    mujoco.mj_forward(m, d)
    ref = rel(p0)
    lifted_rel = None  # the object in the palm frame at the end of the lift
    z0 = float(d.xipos[obj_body][2])
    pp = p0

    def measure():
        r = rel(pp)
        disp = float(np.linalg.norm(r - ref))
        hold = float(np.linalg.norm(r - lifted_rel)) if lifted_rel is not None else 0.0
        gain = float(d.xipos[obj_body][2]) - z0
        bad = d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0  # MuJoCo reset the state
        finite = bool(np.all(np.isfinite(d.qpos)) and np.isfinite(disp) and not bad)
        return disp, hold, gain, finite

    for s in range(steps):
        t = (s + 1) * timestep
        # The palm follows the script kinematically: position and velocity set every step
        # (a 1000 kg body on three slides, gravity compensated), so its motion has a velocity
        # the contacts' friction sees.
        prev = palm_offset(s * timestep)
        nxt = palm_offset(t)
        d.qpos[palm_q] = prev
        d.qvel[palm_v] = (nxt - prev) / timestep
        pp = p0 + nxt
        # Worm lock with a backlash (squeeze_model.cpp): a driven joint opens at most BACKLASH
        # below the largest angle reached, a locked one stays in [that - BACKLASH, that], a
        # coupled one keeps the hand file's limits (the equality holds it to the driven one).
        for kq in jid:
            q = d.qpos[qadr[kq]]
            reached[kq] = max(reached[kq], q)
            lo, hi = base[kq]
            f, j = phalanx[kq]
            top = min(reached[kq], hi)
            if j < driven[f]:
                low = max(lo, top - BACKLASH)
                m.jnt_range[jid[kq]] = [low, max(top, low + 1e-6)]
            elif j == driven[f]:
                m.jnt_range[jid[kq]] = [min(max(lo, top - BACKLASH), hi - 1e-6), hi]
            else:
                m.jnt_range[jid[kq]] = [lo, hi]
        mujoco.mj_step(m, d)
        # Breakaway: the driven phalanx touches the object and has stalled, or is at its limit.
        n = d.ncon
        touch = set()
        if n:
            g1, g2 = d.contact.geom1[:n], d.contact.geom2[:n]
            for a_, b_ in zip(g1, g2):
                if obj_geom[a_] and geom_link[b_] >= 0:
                    touch.add(int(geom_link[b_]))
                elif obj_geom[b_] and geom_link[a_] >= 0:
                    touch.add(int(geom_link[a_]))
        for f in range(nf):
            a = driven[f]
            if a + 1 >= len(kj[f]):
                continue
            kq = kj[f][a]
            slow = d.qvel[vadr[kq]] < STALL_FRACTION * SPEED
            stall[f] = stall[f] + 1 if slow and int(fingers[f][a]) in touch else 0
            at_lim = q0[kq] + d.qpos[qadr[kq]] >= upper[f][a] - 1e-4
            if stall[f] >= stall_steps or at_lim:
                driven[f] = a + 1
                stall[f] = 0
                set_drive(f)
        if verbose and s % 50 == 0:
            print(f"t={t:.3f} d={np.linalg.norm(rel(pp) - ref):.4f} q={np.round([d.qpos[qadr[k]] for k in jid], 3)} "
                  f"touch={sorted(touch)} driven={driven} ncon={d.ncon}", file=sys.stderr)
            f6 = np.zeros(6)
            for i in range(d.ncon):
                mujoco.mj_contactForce(m, d, i, f6)
                c = d.contact[i]
                print(f"   contact {m.geom_bodyid[c.geom1]}-{m.geom_bodyid[c.geom2]} dist {c.dist:.5f} f {np.round(f6[:3], 3)} mu {c.friction[:2]}",
                      file=sys.stderr)
        if s + 1 == sq_steps:
            ref = rel(pp)
        if s + 1 == lift_steps:
            lifted_rel = rel(pp)
        if (s + 1) % 24 == 0:
            disp, hold, gain, finite = measure()
            # Lost for good: left behind by the rising palm, or moved off in the hand after the lift.
            lag = (pp[2] - p0[2]) - gain
            if not finite or lag > LOST or hold > LOST:
                break
    disp, hold, gain, finite = measure()
    lifted = finite and gain >= LIFT_H - SUCCESS and hold < SUCCESS
    return dict(lifted=bool(lifted), displacement=disp, hold_displacement=hold, height_gain=gain, finite=finite,
                breakaway=driven)


def near_threshold(hold, gain):
    """Distance (m) of a verdict's quantities to their thresholds: the hold displacement to
    SUCCESS, the final lag behind the palm (LIFT_H - height_gain) to SUCCESS; nan-safe (inf)."""
    d = [abs(hold - SUCCESS), abs(LIFT_H - gain - SUCCESS)]
    d = [x for x in d if np.isfinite(x)]
    return min(d) if d else np.inf


def cause(r):
    """A disagreement's likely cause, from the two verdicts' quantities and breakaway states."""
    near = min(near_threshold(r.get("ours_hold_displacement", np.nan), r.get("ours_height_gain", np.nan)),
               near_threshold(r.get("mujoco_hold_displacement", np.nan), r.get("mujoco_height_gain", np.nan)))
    if near < 0.005:
        return "marginal (hold displacement or lag within 5 mm of 2 cm)"
    if r["ours_breakaway"] != r["mujoco_breakaway"]:
        return "breakaway differs (squeeze: which phalanx the motor drove)"
    if r["shape"] == "decomposition":
        return "concave shape (convex pieces; contact with a piece's faces)"
    return "contact model (soft MuJoCo vs hard Bullet contacts: squeeze force, slip)"


def summarize(rows):
    agree = sum(r["ours_lifted"] == r["mujoco_lifted"] for r in rows)
    print(f"verdict agreement: {agree}/{len(rows)} = {agree / max(1, len(rows)):.3f}")
    print(f"held: ours {sum(r['ours_lifted'] for r in rows)}, mujoco {sum(r['mujoco_lifted'] for r in rows)}")
    by_obj = {}
    for r in rows:
        k = r["object"].split("/")[0] + ("" if "/" not in r["object"] else "/*")
        a = by_obj.setdefault(k, [0, 0, 0, 0])
        a[0] += 1
        a[1] += r["ours_lifted"] == r["mujoco_lifted"]
        a[2] += r["ours_lifted"]
        a[3] += r["mujoco_lifted"]
    for k, (n, ag, o, mj) in sorted(by_obj.items()):
        print(f"  {k:10s} {n:4d} grasps, agree {ag:4d} ({ag / n:.3f}); held ours {o}, mujoco {mj}")
    by_source = {}
    for r in rows:
        by_source.setdefault(r["source"], []).append(r)
    for src, rs in sorted(by_source.items()):
        ag = sum(r["ours_lifted"] == r["mujoco_lifted"] for r in rs)
        print(f"  source {src:18s} {len(rs):4d} grasps, agree {ag:4d} ({ag / len(rs):.3f}); held ours "
              f"{sum(r['ours_lifted'] for r in rs)}, mujoco {sum(r['mujoco_lifted'] for r in rs)}")
    executed = [r for r in rows if r["source"].startswith("executed_")]
    if executed:
        ag = sum(r["ours_lifted"] == r["mujoco_lifted"] for r in executed)
        print(f"executed grasps (the planners'): agree {ag}/{len(executed)} = {ag / len(executed):.3f}")
    dis = [r for r in rows if r["ours_lifted"] != r["mujoco_lifted"]]
    causes = {}
    for r in dis:
        causes.setdefault(cause(r), []).append(r)
    print(f"disagreements: {len(dis)} (ours lifted, MuJoCo not: {sum(r['ours_lifted'] for r in dis)}; "
          f"MuJoCo lifted, ours not: {sum(not r['ours_lifted'] for r in dis)})")
    for c, rs in sorted(causes.items(), key=lambda kv: -len(kv[1])):
        print(f"  {len(rs):3d}  {c}")
        for r in rs:
            print(f"         {r['object']:10s} {r['source']:17s} #{r['grasp']:<3d} {r['shape']:13s} "
                  f"ours {r['ours_displacement'] * 100:6.2f} cm hold {r.get('ours_hold_displacement', np.nan) * 100:5.2f} "
                  f"gain {r.get('ours_height_gain', np.nan) * 100:6.2f} (break {r['ours_breakaway']}), "
                  f"mujoco {r['mujoco_displacement'] * 100:6.2f} cm hold {r.get('mujoco_hold_displacement', np.nan) * 100:5.2f} "
                  f"gain {r.get('mujoco_height_gain', np.nan) * 100:6.2f} (break {r['mujoco_breakaway']})")


def load(path):
    """One exported object (bench/lift_heldset.py's .npz) as a dict, and its hand (the JSON)."""
    with np.load(path, allow_pickle=False) as zf:
        z = {k: zf[k] for k in zf.files}
    return z, json.loads(str(z["hand_json"]))


def ours(z, key, g):
    """Our exported value (nan when an older export lacks the field)."""
    return float(z[key][g]) if key in z else float("nan")


def positive_or_zero(text):
    v = float(text)
    if not (np.isfinite(v) and v >= 0):
        raise argparse.ArgumentTypeError(f"expected a torque > 0 (N m) or 0 (the hand file's), got {text}")
    return v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("heldset", help="directory of bench/lift_heldset.py's .npz files")
    ap.add_argument("--out", default="bench/results/lift_mujoco.json")
    ap.add_argument("--timestep", type=float, default=0.001)
    ap.add_argument("--max-grasps", type=int, default=0, help="per file (0: all)")
    ap.add_argument("--finger-torque", type=positive_or_zero, default=0.0,
                    help="N m, > 0: every motor's torque limit; 0 (default): the hand file's torque_nm per joint")
    ap.add_argument("--summary-only", action="store_true", help="summarize an existing --out file")
    a = ap.parse_args()
    if a.summary_only:
        with open(a.out) as f:
            summarize(json.load(f))
        return
    rows = []
    t0 = time.time()
    for path in sorted(glob.glob(os.path.join(a.heldset, "*.npz"))):
        z, hand = load(path)
        n = len(z["lifted"]) if a.max_grasps <= 0 else min(a.max_grasps, len(z["lifted"]))
        for g in range(n):
            r = replay(z, g, hand, a.timestep, finger_torque=a.finger_torque)
            rows.append(dict(object=str(z["name"]), source=str(z["source"][g]), grasp=g, shape=str(z["shape"][g]),
                             ours_lifted=bool(z["lifted"][g]), ours_displacement=float(z["displacement"][g]),
                             ours_hold_displacement=ours(z, "hold_displacement", g),
                             ours_height_gain=ours(z, "height_gain", g),
                             ours_breakaway=[int(x) for x in z["breakaway"][g]],
                             mujoco_lifted=r["lifted"], mujoco_displacement=r["displacement"],
                             mujoco_hold_displacement=r["hold_displacement"], mujoco_height_gain=r["height_gain"],
                             mujoco_finite=r["finite"], mujoco_breakaway=[int(x) for x in r["breakaway"]]))
        agree = sum(r["ours_lifted"] == r["mujoco_lifted"] for r in rows)
        print(f"{os.path.basename(path)}: {n} grasps; total {len(rows)}, agree {agree} ({time.time() - t0:.0f} s)",
              file=sys.stderr, flush=True)
    summarize(rows)
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
