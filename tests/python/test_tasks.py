"""Part labels of the procedural objects and the task rules (data files)."""
import json

import numpy as np
import pytest

from bayesgrasp.models.tasks import load_task_file, load_tasks, task_categories, task_rule
from bayesgrasp.objects import load_object
from bayesgrasp.objects.parts import load_part_labels


def _areas(o):
    V, F = o.vertices, o.faces
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


@pytest.mark.parametrize("name", ["mug", "mug2", "pitcher", "mug/0", "mug/5"])
def test_vessel_parts_lie_where_they_belong(name):
    o = load_object(name)
    assert o.part_names == ("body", "rim", "handle")
    C = o.vertices[o.faces].mean(axis=1)
    p = o.params
    handle = o.parts == 2
    # every handle triangle is on the +x side beyond the body, every rim triangle near the top
    assert handle.any() and np.all(C[handle, 0] > p["r_bottom"] * 0.8)
    rim = o.parts == 1
    assert rim.any() and np.all(C[rim, 2] > p["height"] - 1.5 * p["wall"])
    # the handle's area is about its tube's lateral area (perimeter x length), not the body's
    a = _areas(o)
    perimeter = np.pi * (p["handle_width"] + p["handle_thickness"]) / 2
    assert 0.3 < a[handle].sum() / (perimeter * np.pi * (p["handle_z"][1] - p["handle_z"][0]) / 2 + 1e-9) < 3
    assert a[o.parts == 0].sum() > 5 * a[handle].sum()


def test_bottle_parts_are_ordered_by_height():
    o = load_object("bottle/4")
    assert o.part_names == ("body", "shoulder", "neck", "cap")
    z = o.vertices[o.faces].mean(axis=1)[:, 2]
    means = [z[o.parts == i].mean() for i in range(4)]
    assert means == sorted(means)
    assert z[o.parts == 3].min() >= o.params["height"] - o.params["cap_height"] - 1e-9


@pytest.mark.parametrize("name, parts", [("hammer/0", ("handle", "head")), ("knife/1", ("handle", "blade"))])
def test_tool_parts_split_along_the_handle_axis(name, parts):
    o = load_object(name)
    assert o.part_names == parts
    x = o.vertices[o.faces].mean(axis=1)[:, 0]
    assert x[o.parts == 0].max() < x[o.parts == 1].max() and x[o.parts == 0].min() < x[o.parts == 1].min()


def test_labels_survive_a_rigid_transform_and_user_label_files(tmp_path):
    o = load_object("cube")
    assert o.part_names == ("body",) and np.all(o.parts == 0)
    T = np.eye(4)
    T[:3, 3] = (0.1, 0, 0)
    assert np.array_equal(o.transformed(T).parts, o.parts)
    path = tmp_path / "box.stl"
    o.save(path)
    labels = (np.arange(o.n_faces) % 2).tolist()
    (tmp_path / "box.parts.json").write_text(json.dumps({"parts": ["a", "b"], "faces": labels}))
    from bayesgrasp.objects import load_mesh

    m = load_mesh(path)
    assert m.part_names == ("a", "b") and m.parts.tolist() == labels
    assert m.part_of_faces([0, 1]).tolist() == ["a", "b"]
    (tmp_path / "box.parts.json").write_text(json.dumps({"parts": ["a"], "faces": [0, 1]}))
    with pytest.raises(ValueError, match="expected 12, one per triangle of the mesh file in file order"):
        load_mesh(path)
    with pytest.raises(ValueError, match="labels must lie"):
        load_part_labels(_write(tmp_path / "x.json", {"parts": ["a"], "faces": [1] * 12}), 12)


def _write(path, doc):
    path.write_text(json.dumps(doc))
    return path


def test_every_category_with_objects_has_tasks_that_name_real_parts():
    assert task_categories() == ["bottle", "hammer", "knife", "mug"]
    for cat, member in [("mug", "mug/0"), ("bottle", "bottle/0"), ("hammer", "hammer/0"), ("knife", "knife/0")]:
        parts = set(load_object(member).part_names)
        for rule in load_tasks(cat).values():
            assert set(rule.allowed_parts) <= parts and set(rule.targets) <= parts
    assert set(load_tasks("mug")) == {"top", "side", "handle"}


def test_approach_rules_by_hand():
    top = task_rule("mug", "top")
    down, tilted, sideways = [0, 0, -1], [np.sin(np.radians(20)), 0, -np.cos(np.radians(20))], [-1, 0, 0]
    assert top.approach_ok([down, tilted, sideways]).tolist() == [True, False, False]
    side = task_rule("mug", "side")
    # coming from -x (opposite the handle at +x) moves along +x; from +y moves along -y; from +x is the handle
    assert side.approach_ok([[1, 0, 0], [0, -1, 0], [-1, 0, 0], [0, 0, -1]]).tolist() == [True, True, False, False]
    handle = task_rule("mug", "handle")
    assert handle.approach_ok([[-1, 0, 0], [1, 0, 0]]).tolist() == [True, False]
    tool = task_rule("knife", "handle")
    # tools are held off the table: from below (moving up, +z) is allowed too, along the handle never
    assert not tool.table and task_rule("mug", "top").table
    assert tool.approach_ok([[0, 0, -1], [0, 1, 0], [-1, 0, 0], [0, 0, 1]]).tolist() == [True, True, False, True]
    from dataclasses import replace
    on_table = replace(tool, table=True)                           # the same rule for a tool on a table
    assert on_table.approach_ok([[0, 0, -1], [0, 1, 0], [0, 0, 1], [0, 0.6, 0.8]]).tolist() == [True, True, False, False]


def test_a_tool_held_off_the_table_can_be_grasped_around_its_handle():
    from bayesgrasp.world import World

    # from above, across the 2.4 cm handle 5 cm from its end: on a table the hand stops on the
    # table with nothing in it; held off the table the three fingers close on the handle and hold it
    args = ([0, 0, -1], [0.05, 0, 0.012], 0.0)
    on_table = World.single("hammer/0").approach(*args, spread=0.0, lift=True)
    assert on_table.stopped_by_table and not on_table.lifted
    g = World.single("hammer/0", table=False).approach(*args, spread=0.0, lift=True)
    assert not g.stopped_by_table and [c.part for c in g.contacts] == ["handle"] * 3 and g.lifted


def test_contact_rules_by_hand():
    handle = task_rule("mug", "handle")
    assert handle.contacts_ok(["handle", "handle", "body"])
    assert not handle.contacts_ok(["handle", "body", "body"])      # one finger on the handle
    knife = task_rule("knife", "handle")
    assert knife.contacts_ok(["handle", "handle"]) and not knife.contacts_ok(["handle", "blade"])
    assert not knife.contacts_ok(["handle"])                        # too few contacts


@pytest.mark.parametrize("doc, needle", [
    ({"category": "c", "parts": ["a"], "tasks": {"t": {"approach": {}, "contacts": {"allowed": ["z"]}}}}, "unknown parts"),
    ({"category": "c", "parts": ["a"], "tasks": {"t": {"approach": {"from_sky": {}}, "contacts": {"allowed": ["a"]}}}},
     "unknown constraint"),
    ({"category": "c", "parts": ["a"], "tasks": {"t": {"approach": {"from_axis": {"axis": [0, 0, 0], "max_angle_deg": 5}},
                                                       "contacts": {"allowed": ["a"]}}}}, "non-zero"),
    ({"category": "c", "parts": ["a"], "tasks": {}}, "at least one task"),
    ({"category": "c", "parts": ["a"], "table": "no", "tasks": {"t": {"approach": {}, "contacts": {"allowed": ["a"]}}}},
     "'table' must be true or false"),
    ({"category": "c", "parts": ["a"], "tasks": {"t": {"contacts": {"allowed": ["a"]}}}}, "needs 'approach'"),
])
def test_bad_task_files_name_the_problem(tmp_path, doc, needle):
    with pytest.raises(ValueError, match=needle):
        load_task_file(_write(tmp_path / "t.json", doc))


def test_unknown_category_or_task():
    with pytest.raises(ValueError, match="no tasks for 'spoon'"):
        load_tasks("spoon")
    with pytest.raises(ValueError, match="its tasks: top, side, handle"):
        task_rule("mug", "throw")


def _rule_of(approach, table=True):
    from bayesgrasp.models.tasks import _rule

    return _rule("c", "t", {"approach": approach, "contacts": {"allowed": ["a"]}}, ["a", "b"], "t.json: task 't'", table)


def _dirs_from(azimuth_deg, elevation_deg):
    """Approach directions (the hand moves along them) that come from the given azimuth and
    elevation (degrees): the source direction is -d."""
    az, el = np.broadcast_arrays(np.radians(azimuth_deg), np.radians(elevation_deg))
    src = np.column_stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    return -src


def test_every_approach_constraint_at_and_past_its_limits():
    # Oracles from the definitions: from_axis: angle(source, axis) <= max; from_horizontal:
    # |elevation| <= max tilt; from_azimuth: |azimuth - azimuth(axis)| wrapped to [-180, 180)
    # within [min, max]; across_axis: angle(direction, axis line) >= min. 1e-6 deg either side of
    # a limit; limits are inclusive, checked where the angle is exact (0 deg, and 90 deg across).
    eps = 1e-6
    axis = _rule_of({"from_axis": {"axis": [0, 0, 1], "max_angle_deg": 30}})
    assert axis.approach_ok(_dirs_from([0, 0, 90], [60 + eps, 60 - eps, 60 + eps])).tolist() == [True, False, True]
    assert _rule_of({"from_axis": {"axis": [0, 0, 1], "max_angle_deg": 0}}).approach_ok([[0, 0, -1]]).tolist() == [True]
    tilt = _rule_of({"from_horizontal": {"max_tilt_deg": 20}}, table=False)   # from below too
    assert tilt.approach_ok(_dirs_from([45] * 4, [20 - eps, 20 + eps, -20 + eps, -20 - eps])).tolist() == [
        True, False, True, False]
    assert _rule_of({"from_horizontal": {"max_tilt_deg": 0}}).approach_ok([[-1, 0, 0]]).tolist() == [True]
    # an azimuth window around an axis at 30 deg (not on a coordinate axis: both components count)
    c30 = [np.cos(np.radians(30)), np.sin(np.radians(30)), 0]
    az = _rule_of({"from_azimuth": {"axis": c30, "min_angle_deg": 10, "max_angle_deg": 40}})
    got = az.approach_ok(_dirs_from([40 - eps, 40 + eps, 70 - eps, 70 + eps, 30 - 25, 30, 30 - 40 + eps, -10 - eps], 0.0))
    assert got.tolist() == [False, True, True, False, True, False, True, False]
    assert not az.approach_ok([[0, 0, -1]])[0]          # straight down has no azimuth
    exact = _rule_of({"from_azimuth": {"axis": [1, 0, 0], "min_angle_deg": 0, "max_angle_deg": 0}})
    assert exact.approach_ok([[-1, 0, 0], [-1, 1e-3, 0]]).tolist() == [True, False]
    across = _rule_of({"across_axis": {"axis": [1, 0, 0], "min_angle_deg": 60}})
    # the direction's angle to the axis line: 60 + eps, 60 - eps, 120 - eps (the other way round)
    d = [[np.cos(np.radians(a)), 0, -np.sin(np.radians(a))] for a in (60 + eps, 60 - eps, 120 - eps)]
    assert across.approach_ok(d).tolist() == [True, False, True]
    square = _rule_of({"across_axis": {"axis": [1, 0, 0], "min_angle_deg": 90}})
    assert square.approach_ok([[0, 0, -1], [1e-3, 0, -1]]).tolist() == [True, False]


def test_contact_counts_targets_and_keys_are_read_from_the_file(tmp_path):
    doc = {"category": "c", "parts": ["a", "b"], "table": False, "tasks": {"t": {
        "approach": {"from_horizontal": {"max_tilt_deg": 30}},
        "contacts": {"allowed": ["a", "b"], "min_object_contacts": 0, "min_part_contacts": {"a": 0, "b": 2}},
        "targets": ["b"]}}}
    rule = load_task_file(_write(tmp_path / "t.json", doc))["t"]
    assert rule.targets == ("b",) and rule.min_object_contacts == 0 and rule.min_part_contacts == {"a": 0, "b": 2}
    assert rule.table is False and rule.category == "c" and rule.name == "t"
    assert rule.contacts_ok(["b", "b"]) and not rule.contacts_ok(["a", "b"])
    bad = [({"allowed": ["a"], "min_object_contacts": -1}, "contact counts must be non-negative integers"),
           ({"allowed": ["a"], "min_part_contacts": {"a": -1}}, "contact counts must be non-negative integers"),
           ({"allowed": ["a"], "min_part_contacts": {"z": 1}}, r"contacts.min_part_contacts: unknown parts \['z'\]"),
           ({"allowed": ["z"]}, r"contacts.allowed: unknown parts \['z'\]"),
           ({"allowed": ["a"], "colour": 1}, r"keys must be among \['allowed', 'min_object_contacts'")]
    for contacts, needle in bad:
        doc["tasks"]["t"]["contacts"] = contacts
        with pytest.raises(ValueError, match=needle):
            load_task_file(_write(tmp_path / "t.json", doc))
    doc["tasks"]["t"]["contacts"] = {"allowed": ["a"]}
    doc["tasks"]["t"]["targets"] = ["z"]
    with pytest.raises(ValueError, match=r"t.json: task 't'.targets: unknown parts \['z'\]"):
        load_task_file(_write(tmp_path / "t.json", doc))
    doc["colour"] = "red"
    with pytest.raises(ValueError, match=r"unknown keys \['colour'\]$"):
        load_task_file(_write(tmp_path / "t.json", doc))
    with pytest.raises(ValueError, match=r"max_tilt_deg: .*90"):
        _rule_of({"from_horizontal": {"max_tilt_deg": 95}})
    _rule_of({"from_axis": {"axis": [0, 0, 1], "max_angle_deg": 95}})   # up to 180 for the others
