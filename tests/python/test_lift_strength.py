"""The lift test's strength (issue 30): the hand file's actuation, and the force a fingertip
presses a fixed plate with at full torque against the published figure.

A plate (30 x 30 x 1 cm, 90 kg: it stays put) lies on the table; the hand is palm down above it,
one finger's last phalanx broken away (driven by the motor) and its tip 1 mm above the plate.
With no friction the plate pushes only along its normal, so once the phalanx presses still the
contact's moment about the driven joint is the motor's torque (the phalanx's 80 g add ~2%).
The force that moment makes at the phalanx's tip (moment / phalanx length) must be the hand
file's published fingertip force within 10%. Without the worm's backlash the lock holds the
contact's overlap and the force grows past the motor's (the BH8: 26 N, then 34 N and rising,
for its 20 N); without the drive's inertia the short phalanx's impulses are not resolved in the
solver's iterations (the Robotiq 3F: 84% of its torque).
"""
import json

import numpy as np
import pytest
import trimesh

from bayesgrasp import physics
from bayesgrasp.hand import Hand

PLATE_TOP = 0.01


def _published(hand: Hand) -> float:
    with open(hand.path) as f:
        return float(json.load(f)["actuation"]["fingertip_force_n"])


def _finger(hand: Hand, finger: int):
    """The finger's joint indices (in q) and link indices, base to tip."""
    links = hand.phalanx_links[finger]
    name = hand.links[links[0]].split("/")[0]
    return [j for j, n in enumerate(hand.joint_names) if n.split("/")[0] == name], links


def _pressing_finger(hand: Hand, finger: int):
    """Open joints with the finger's last phalanx 0.3 rad past the closing law (broken away: the
    motor drives it), and the palm-down pose that puts that phalanx 1 mm above the plate."""
    joints, links = _finger(hand, finger)
    q = hand.open_joints(0.0)
    last = joints[-1]
    q[last] = min(q[last] + 0.3, hand.joint_limits[last][1] - 0.05)
    down = np.diag([1.0, -1.0, -1.0, 1.0])  # the approach axis (+z of the hand) pointing down
    shapes = [s for s in hand.link_geometry(q, down) if s.link == links[-1]]
    lowest = min(min(s.p0[2], s.p1[2]) - s.radius for s in shapes)
    pose = down.copy()
    pose[2, 3] = PLATE_TOP + 1e-3 - lowest
    return q, pose


def _press(hand: Hand, finger: int, finger_torque: float = 0.0):
    """The moment (N m) of the plate's contacts about the driven joint, at each traced step of
    the squeeze's last 40% (the phalanx pressing still), and the finger's joints."""
    joints, links = _finger(hand, finger)
    q, pose = _pressing_finger(hand, finger)
    plate = trimesh.creation.box([0.3, 0.3, 0.01])
    plate.apply_translation([0.0, 0.0, PLATE_TOP / 2])
    tester = physics.LiftTester(hand.path, plate.vertices, plate.faces, density=1e5, shape="hull", mu=0.0,
                                squeeze_time=0.5, finger_torque=finger_torque)
    r = tester.run(pose, q, trace_every=2)
    tr = r.trace
    link = links[-1]
    L = hand.joint_limits
    t = np.asarray(tr.time)
    samples = np.flatnonzero((t > 0.6 * tr.phase_ends[0]) & (t <= tr.phase_ends[0]))
    assert all(d[finger] == len(joints) - 1 for d in np.asarray(tr.driven)[samples]), "the last phalanx is driven"
    cs, cl = np.asarray(tr.contact_sample), np.asarray(tr.contact_link)
    cp, cn, cf = np.asarray(tr.contact_point), np.asarray(tr.contact_normal), np.asarray(tr.contact_force)
    moments = []
    for s in samples:
        P = hand.link_poses(np.clip(np.asarray(tr.joints)[s], L[:, 0], L[:, 1]), pose)[link]
        axis, origin = P[:3, 1], P[:3, 3]  # closing turns the phalanx about its +y
        m = np.flatnonzero((cs == s) & (cl == link))
        moments.append(sum(np.cross(cp[i] - origin, cf[i] * cn[i]) @ axis for i in m))
    return np.asarray(moments), joints


@pytest.mark.parametrize("name,finger", [("barrett_bh8", 2), ("robotiq_3f", 2)])
def test_fingertip_force_on_a_fixed_plate_is_the_published_figure(name, finger):
    hand = Hand.load(name)
    moments, joints = _press(hand, finger)
    with open(hand.path) as f:
        spec = json.load(f)
    length = spec["fingers"][finger]["phalanges"][-1]["length"]
    tip_force = np.abs(moments) / length
    published = _published(hand)
    assert np.all(moments < 0), "the plate pushes the phalanx open"
    # The motor's torque limit is the hand file's, and pressing still it is all the plate sees.
    assert np.median(np.abs(moments)) == pytest.approx(hand.joint_torques[joints[-1]], rel=0.1)
    assert np.median(tip_force) == pytest.approx(published, rel=0.1), tip_force


def test_the_torque_override_scales_the_force():
    hand = Hand.load("barrett_bh8")
    q, pose = _pressing_finger(hand, 2)
    link = hand.phalanx_links[2][-1]
    plate = trimesh.creation.box([0.3, 0.3, 0.01])
    plate.apply_translation([0.0, 0.0, PLATE_TOP / 2])
    force = {}
    for torque in (0.5, 2.0):
        t = physics.LiftTester(hand.path, plate.vertices, plate.faces, density=1e5, shape="hull", mu=0.0,
                               finger_torque=torque)
        tr = t.run(pose, q, trace_every=2).trace
        end = np.flatnonzero(np.asarray(tr.time) <= tr.phase_ends[0])[-1]
        m = (np.asarray(tr.contact_sample) == end) & (np.asarray(tr.contact_link) == link)
        force[torque] = np.asarray(tr.contact_force)[m].sum()
    assert force[2.0] / force[0.5] == pytest.approx(4.0, rel=0.15)


def test_a_hand_without_torques_is_refused_unless_overridden():
    hand = Hand.load("barrett_bh8")
    with open(hand.path) as f:
        spec = json.load(f)
    for finger in spec["fingers"]:
        for ph in finger["phalanges"]:
            ph["torque_nm"] = 0.0   # strength unknown (a missing key is refused when the file loads)
    weak = Hand.from_json(json.dumps(spec))
    spec["fingers"][0]["phalanges"][0].pop("torque_nm")
    with pytest.raises(ValueError, match="missing key 'torque_nm'"):
        Hand.from_json(json.dumps(spec))
    box = trimesh.creation.box([0.05, 0.05, 0.05])
    with pytest.raises(ValueError, match=r"no torque for finger1/proximal .*torque_nm.*finger_torque"):
        physics.LiftTester(weak.core, box.vertices, box.faces, shape="hull")
    assert physics.LiftTester(weak.core, box.vertices, box.faces, shape="hull", finger_torque=1.0).mass > 0
