import numpy as np
import pytest

from bayesgrasp.sim import GraspSimulator
from bayesgrasp.world import World


def test_top_grasp_keeps_the_finger_sweep_above_the_table():
    world = World.single("mug")
    V, F = world.vertices, world.faces
    # The mug (9.5 cm) is lower than the Barrett's fingers reach below the palm (about 10.6 cm):
    # stopping at the first contact (clearance < 0) lets the fingers strike the table.
    first_contact = GraspSimulator(world.hand, V, F, table_clearance=-1.0).top_grasp(0.0, 0.0, 0.3, spread=0.0)
    assert first_contact.contact_on_table.any()
    clear = GraspSimulator(world.hand, V, F, table_clearance=0.005).top_grasp(0.0, 0.0, 0.3, spread=0.0)
    assert not clear.contact_on_table.any()
    assert int((~clear.contact_on_table).sum()) >= 3          # all three fingers on the mug
    # the palm is raised so that the deepest point of the closing sweep is 5 mm above the table
    assert clear.hand_pose[2, 3] > first_contact.hand_pose[2, 3]


def test_grasp_batch_scores_each_grasp_like_a_single_grasp():
    world = World.single("cylinder", pose=(0.05, 0.02, 0.4))
    grasps = np.array([[0.0, 0.0, 0.0], [0.01, -0.005, 0.7], [0.0, 0.01, 1.9]])
    b = world.grasp_batch(grasps, spread=0.0, threads=2)
    for i, g in enumerate(grasps):
        one = world.grasp(*g, spread=0.0)
        np.testing.assert_allclose(b["joint_angles"][i], one["joint_angles"])
        assert b["epsilon"][i] == pytest.approx(one["epsilon"], rel=1e-12, abs=1e-15)


def test_world_rejects_bad_parameters():
    with pytest.raises(ValueError, match="mu"):
        World.single("cube", mu=-1.0)
    with pytest.raises(ValueError, match="grasps"):
        World.single("cube").grasp_batch(np.zeros((2, 2)))
