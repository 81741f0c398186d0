"""The part-aware plan's check (issue 29) on oracles that follow from the model's labels: a mug's
handle grasp (two handle contacts, from the handle's side) passes the handle rule and fails the
side rule, a body grasp from the far side does the opposite, wherever the registration puts the
model; the choice never takes a rejected candidate while one passes."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.hand import Hand
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.vision import RegistrationResult
from bayesgrasp.planners.category import CategoryPlanner, CategorySettings, TaskGrasp
from bayesgrasp.planners.part_check import (PartCheck, best_passing, check_candidates, choose, choose_by_lift,
                                            choose_lazily, model_world)

HAND = Hand.load("barrett_bh8")
MUG = "mug/1"     # handle along +x, labelled "handle"; the body "body", the rim "rim"


def approach(direction, z, roll=0.0):
    return Hand.approach_pose(np.asarray(direction, float), roll, np.array([0.0, 0.0, z]))


HANDLE = approach((-1, 0, 0), 0.06)    # from +x, through the handle into the body
BODY = approach((1, 0, 0), 0.06)       # from -x, away from the handle
ACROSS = approach((0, 1, 0), 0.05, np.pi / 2)   # from -y, a side the side task allows; a finger reaches the handle


def placed(yaw, t):
    T = np.eye(4)
    c, s = np.cos(yaw), np.sin(yaw)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = t
    return T


def parts_on_model(pose, roll=0.0):
    """The contacts' parts of the approach along ``pose``, read directly from the model's world."""
    w = model_world(MUG, HAND, True)
    b = w.approach_batch(pose[None, :3, 2], pose[None, :3, 3], roll, spread=0.0, frame="world")
    return sorted(p for p in b.contact_part if p is not None)


def test_the_oracle_grasps_touch_what_they_should():
    assert parts_on_model(HANDLE).count("handle") >= 2
    assert set(parts_on_model(BODY)) == {"body"} and len(parts_on_model(BODY)) >= 2


@pytest.mark.parametrize("yaw, t", [(0.0, (0, 0, 0)), (2.1, (0.07, -0.04, 0.0)), (-0.8, (-0.05, 0.03, 0.0))])
def test_handle_and_body_grasps_score_the_rules_one_and_zero_wherever_the_model_is_registered(yaw, t):
    T = placed(yaw, t)
    regs = [RegistrationResult.known(MUG, T, phi=0.9), RegistrationResult.known("mug/2", placed(0.3, (0.2, 0.2, 0)), phi=0.0)]
    A = np.array([T @ HANDLE, T @ BODY])                     # the candidates in the scene
    handle = check_candidates(HAND, task_rule("mug", "handle"), A, 0.0, regs, [1.0, 0.0])
    side = check_candidates(HAND, task_rule("mug", "side"), A, 0.0, regs, [1.0, 0.0])
    np.testing.assert_array_equal(handle.p_rule, [1.0, 0.0])
    np.testing.assert_array_equal(side.p_rule, [0.0, 1.0])
    assert sorted(handle.parts[0][0]) == parts_on_model(HANDLE) and sorted(side.parts[1][0]) == parts_on_model(BODY)
    assert handle.parts[0][1] == [] and not handle.rule_ok[:, 1].any()    # a model of weight 0 is not closed
    np.testing.assert_array_equal(handle.p_success, handle.p_rule * handle.held[:, 0])


def test_a_side_grasp_from_an_allowed_side_that_touches_the_handle_fails_on_its_contacts():
    side = task_rule("mug", "side")
    assert side.approach_ok(np.array([ACROSS[:3, 2], BODY[:3, 2]])).all()      # both directions are allowed
    assert "handle" in parts_on_model(ACROSS, roll=np.pi / 2)
    T = placed(-2.4, (0.04, 0.06, 0.0))
    c = check_candidates(HAND, side, np.array([T @ ACROSS, T @ BODY]), 0.0, [RegistrationResult.known(MUG, T, phi=1.0)], [1.0])
    np.testing.assert_array_equal(c.p_rule, [0.0, 1.0])
    assert "handle" in c.parts[0][0] and set(c.parts[1][0]) == {"body"}


def test_the_weights_add_over_the_models_where_the_rule_holds():
    T0, T1 = placed(0.0, (0, 0, 0)), placed(np.pi, (0, 0, 0))    # the second copy turned half a turn
    regs = [RegistrationResult.known(MUG, T0, phi=1.0), RegistrationResult.known(MUG, T1, phi=1.0)]
    # in the scene: from +x, which is the first copy's handle side and the second copy's far side
    c = check_candidates(HAND, task_rule("mug", "handle"), HANDLE[None], 0.0, regs, [0.7, 0.3])
    assert c.rule_ok.tolist() == [[True, False]] and c.p_rule[0] == pytest.approx(0.7)
    c = check_candidates(HAND, task_rule("mug", "side"), HANDLE[None], 0.0, regs, [0.7, 0.3])
    assert c.rule_ok.tolist() == [[False, True]] and c.p_rule[0] == pytest.approx(0.3)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.1, 0.5, 1.0]), st.floats(0, 10)), min_size=1, max_size=30))
def test_the_choice_never_takes_a_rejected_candidate_while_one_passes(rows):
    p, J = np.array(rows).T
    k = choose(p, J, tiebreak=0.1)
    if (p > 0).any():
        assert p[k] > 0
        assert p[k] + 0.1 * J[k] / max(J.max(), 1e-300) >= (p + 0.1 * J / max(J.max(), 1e-300))[p > 0].max() - 1e-12
    else:
        assert J[k] == J.max()


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 40), st.integers(1, 4), st.integers(0, 2**31 - 1), st.booleans())
def test_the_lazy_choice_is_the_full_choice(K, M, seed, product):
    """Held computed only where it could change the answer gives what knowing it everywhere gives."""
    rng = np.random.default_rng(seed)
    rule = rng.random((K, M)) < 0.5
    held = rng.random((K, M)) < 0.6
    w = rng.dirichlet(np.ones(M))
    J = np.round(rng.random(K), 1) * (rng.random(K) < 0.9)          # ties and zeros on purpose
    full = choose(((rule & held).astype(float) @ w), J, 0.1, product)
    lazy = PartCheck(rule, np.zeros((K, M), bool), w, [[[]] * M] * K, np.zeros(K, bool),
                     lambda rows: held[rows] & rule[rows])
    assert choose_lazily(lazy, J, 0.1, product, batch=3) == full


def _random_check(K, M, seed):
    """A PartCheck of random rule / held / lifted verdicts (held and lifted computed on demand) and
    the full truth: (check, J, P(rule, held), P(rule, held, lifted), weights)."""
    rng = np.random.default_rng(seed)
    rule, held, lifted = (rng.random((K, M)) < 0.5), (rng.random((K, M)) < 0.6), (rng.random((K, M)) < 0.4)
    w = rng.dirichlet(np.ones(M))
    J = np.round(rng.random(K), 1) * (rng.random(K) < 0.9)          # ties and zeros on purpose
    check = PartCheck(rule, np.zeros((K, M), bool), w, [[[]] * M] * K, np.zeros(K, bool),
                      lambda rows: held[rows] & rule[rows], lambda rows, need: lifted[rows] & need)
    return check, J, (rule & held).astype(float) @ w, (rule & held & lifted).astype(float) @ w


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 40), st.integers(1, 4), st.integers(0, 2**31 - 1), st.integers(1, 6))
def test_the_best_passing_candidates_are_the_top_of_the_full_ranking(K, M, seed, n):
    """Held computed lazily, the n best passing candidates score as the n best with held known
    everywhere (ties may swap rows of equal score)."""
    check, J, p, _ = _random_check(K, M, seed)
    score = p + 0.1 * J / (J.max() if J.max() > 0 else 1.0)
    expected = np.sort(score[p > 0])[::-1][:n]
    got = best_passing(check, J, n, 0.1, batch=3)
    assert (p[got] > 0).all()
    np.testing.assert_allclose(score[got], expected)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 40), st.integers(1, 4), st.integers(0, 2**31 - 1), st.integers(1, 6))
def test_the_lift_decides_among_the_best_and_never_takes_one_that_drops_on_every_model(K, M, seed, n):
    check, J, _, p_lift = _random_check(K, M, seed)
    rows = best_passing(_random_check(K, M, seed)[0], J, n, 0.1)
    chosen, tested, p = choose_by_lift(check, J, n, 0.1)
    assert tested == len(rows)
    if not (p_lift[rows] > 0).any():
        assert chosen is None and p == 0.0
        return
    top = J.max() if J.max() > 0 else 1.0
    assert chosen in rows and p_lift[chosen] > 0 and p == pytest.approx(p_lift[chosen])
    lifting = rows[p_lift[rows] > 0]
    assert p_lift[chosen] + 0.1 * J[chosen] / top >= (p_lift[lifting] + 0.1 * J[lifting] / top).max() - 1e-12


def test_the_part_aware_plan_returns_a_checked_candidate():
    """One model, its handle grasp and its body grasp as demonstrations of the handle task: the plan
    must land on one that passes the handle rule on the model (and say so)."""
    T = placed(0.5, (0.03, 0.01, 0))
    gs = [TaskGrasp(MUG, "handle", BODY, 0.0, 0.3, True), TaskGrasp(MUG, "handle", HANDLE, 0.0, 0.1, True)]
    s = CategorySettings(method="part-aware", part_candidates=12, pso_particles=6, pso_iter=3)
    plan = CategoryPlanner(HAND, gs, [RegistrationResult.known(MUG, T, phi=1.0)], settings=s, seed=1,
                           rule=task_rule("mug", "handle")).plan()
    assert plan.ok and plan.extra["passing_rule"] >= 1 and plan.extra["p_rule"] == 1.0
    assert plan.extra["contact_parts_on_models"][MUG].count("handle") >= 2
    with pytest.raises(ValueError, match="part-aware: needs the task's rule"):
        CategoryPlanner(HAND, gs, [RegistrationResult.known(MUG, T, phi=1.0)], settings=s)


def test_fusion_part_aware_takes_a_passing_grasp_and_multiplies_eq46():
    """Eq. 4.6 alone takes the task grasp at (0.02, 0.01, 0.3); a part check that passes only
    grasps 5 mm or more to its +x moves the choice there, and the round reports P there."""
    from testkit import analytic

    from bayesgrasp.belief.model_mixture import ModelMixtureBelief
    from bayesgrasp.planners.fusion import FusionPlanner, FusionSettings

    def part(C, belief):
        ok = (C[:, 0] >= 0.025)[:, None]
        return PartCheck(ok, ok.copy(), np.array([0.8]), [[[]] for _ in C])

    s = FusionSettings(task_term="part-aware", part_candidates=40, part_translation=0.01)
    belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0.02, 0.01, 0.3]], s, seed=2)
    p = FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])], seed=3, part_check=part).plan()
    assert p.action[0] >= 0.025 and p.part == 0.8
    assert p.objective == pytest.approx(p.task * p.stability, rel=1e-9)   # ranked by Eq. 4.6's product from round 1
    plain = FusionPlanner(ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0.02, 0.01, 0.3]], FusionSettings(),
                                             seed=2), [np.array([[0.0, 0.0, 0.0]])], seed=3).plan()
    assert plain.action[0] < 0.025 and plain.part is None
    with pytest.raises(ValueError, match="part-aware: needs a part check"):
        FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])])


def test_the_top_grasp_check_reads_the_models_parts_at_their_poses():
    """A top grasp over the mug's rim from above obeys the top rule wherever the belief puts the
    model, when the grasp is moved with it; a grasp 30 cm away touches nothing."""
    from bayesgrasp.belief import absolute_planar_pose
    from bayesgrasp.planners.part_check import check_top_grasps

    rule = task_rule("mug", "top")
    w = model_world(MUG, HAND, True)
    rel = np.array([[x, 0.0, yaw] for x in (-0.03, -0.02, 0.0, 0.02) for yaw in (0.0, 0.8, 1.6)])
    b = w.grasp_batch(rel, spread=0.0)
    ok = [rule.contacts_ok([p for p in b.contact_part[b.contacts.offsets[k]:b.contacts.offsets[k + 1]] if p])
          and not b.collision_at_start[k] for k in range(len(rel))]
    assert any(ok) and not all(ok)
    pose = np.array([0.05, -0.02, 1.1])
    G = np.vstack([absolute_planar_pose(rel, pose[None, :]), [[0.2, 0.2, 0.0]]])
    c = check_top_grasps(HAND, rule, G, [MUG, "mug/2"], [pose, [0, 0, 0]], [1.0, 0.0], spread=0.0)
    assert c.rule_ok[:, 0].tolist() == ok + [False] and not c.rule_ok[:, 1].any()


def test_epsilon_of_chosen_rows_is_the_batch_epsilon():
    """A batch closed without quality, its epsilon computed later for some rows, equals the epsilon
    of the same batch scored at once."""
    w = model_world(MUG, HAND, True)
    a = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    D = -np.c_[np.cos(a), np.sin(a), np.zeros_like(a)]
    P = np.tile([0.0, 0.0, 0.06], (len(a), 1))
    full = w.approach_batch(D, P, 0.0, spread=0.0, frame="world")
    lazy = w.approach_batch(D, P, 0.0, spread=0.0, frame="world", quality=False)
    start = np.asarray(lazy.collision_at_start, bool)
    assert np.isnan(lazy.epsilon[~start]).all() and (full.epsilon > 0).any()
    rows = np.array([7, 0, 3, 11])
    np.testing.assert_allclose(w.epsilon_of(lazy, rows), full.epsilon[rows], rtol=1e-9, atol=1e-12)



def _stretched(name=MUG, sx=1.3, lift=0.0):
    """The model stretched along x (its handle further out) and raised by ``lift``: the same
    triangles and labels, another shape, as an ObjectModel in the model's frame."""
    from bayesgrasp.objects import ObjectModel, load_object

    m = load_object(name)
    V = m.vertices * [sx, 1.0, 1.0] + [0.0, 0.0, lift]
    return ObjectModel(f"{m.name}~stretched", V, m.faces, density=m.density, parts=m.parts, part_names=m.part_names)


@pytest.mark.parametrize("lift", [0.0, 0.01])
def test_closing_on_a_given_shape_is_closing_on_that_shape_placed_by_the_registration(lift):
    """check_candidates(shapes=[S]) gives, candidate by candidate, the parts that the hand touches
    on S itself placed at the registration (S resting on the table: a shape whose bottom moved is
    put back on it, and the candidates move with it, keeping their place on the shape)."""
    from bayesgrasp.world import World

    S = _stretched(lift=lift)
    T = placed(0.7, (0.04, -0.02, 0.0))
    rule = task_rule("mug", "handle")
    A = np.array([T @ approach((-np.cos(a), -np.sin(a), 0.0), z) for a in (-0.4, 0.0, 0.5) for z in (0.03, 0.06)])
    check = check_candidates(HAND, rule, A, 0.0, [RegistrationResult.known(MUG, T, phi=1.0)], [1.0],
                             shapes=[S], resolve=False)
    direct = World.single(S, pose=(0.04, -0.02, 0.7), hand=HAND, keep_origin=True)
    down = np.eye(4)
    down[2, 3] = -lift                                       # S put back on the table; the candidates move with it
    A = np.array([T @ down @ np.linalg.inv(T) @ a for a in A])
    rolls = np.array([Hand.approach_roll(a) for a in A])
    b = direct.approach_batch(A[:, :3, 2], A[:, :3, 3], rolls, spread=0.0, frame="world")
    for k in range(len(A)):
        lo, hi = b.contacts.offsets[k], b.contacts.offsets[k + 1]
        assert sorted(check.parts[k][0]) == sorted(p for p in b.contact_part[lo:hi] if p is not None)
    if lift == 0.0:
        assert check.p_rule.max() == 1.0                    # a handle grasp passes on the stretched shape
    with pytest.raises(ValueError, match="shapes: one per registration"):
        check_candidates(HAND, rule, A, 0.0, [RegistrationResult.known(MUG, T)], [1.0], shapes=[S, S])


def test_the_warped_method_checks_its_candidates_on_the_models_warped_onto_the_cloud():
    """A stretched mug seen as a cloud, mug/1 registered onto it: the warped method's shapes are
    mug/1 warped to within millimetres of the stretched mug, and its plan passes the handle rule
    there."""
    from scipy.spatial import cKDTree

    from bayesgrasp.vision import model_samples

    S = _stretched()
    T = placed(-0.5, (0.0, 0.03, 0.0))
    P, _ = model_samples(S, samples=2500, seed=2)
    cloud = P @ T[:3, :3].T + T[:3, 3]
    regs = [RegistrationResult.known(MUG, T, phi=1.0)]
    grasps = [TaskGrasp(model=MUG, task="handle", pose=HANDLE, spread=0.0, epsilon=0.2, lifted=True)]
    planner = CategoryPlanner(HAND, grasps, regs, cloud=cloud, rule=task_rule("mug", "handle"),
                              settings=CategorySettings(method="warped", part_candidates=16), seed=1)
    (shape,) = planner.warped_models()
    surface = cKDTree(model_samples(S, samples=30000, seed=3)[0])
    assert np.median(surface.query(shape.vertices)[0]) < 0.002
    assert shape.part_names == S.part_names and np.array_equal(shape.parts, S.parts)
    plan = planner.plan()
    assert plan.ok and plan.method == "warped" and plan.extra["p_rule"] == 1.0
    # the lift test on the warped shape decided among the best candidates, and the chosen one lifts there
    assert plan.extra["lift_checked"] >= 1 and plan.extra["p_lifted"] == 1.0
    from bayesgrasp.world import World
    direct = World.single(shape, pose=(0.0, 0.03, -0.5), hand=HAND, keep_origin=True)
    g = direct.approach(plan.pose[:3, 2], plan.pose[:3, 3], Hand.approach_roll(plan.pose), spread=plan.spread,
                        frame="world", lift=True)
    assert g.lifted
    # another task on the same view reuses the warped models: the same plan, no warp recomputed
    again = CategoryPlanner(HAND, grasps, regs, cloud=cloud, rule=task_rule("mug", "handle"), warped=[shape],
                            settings=CategorySettings(method="warped", part_candidates=16), seed=1)
    assert again.warped_models()[0] is shape
    np.testing.assert_array_equal(again.plan().pose, plan.pose)
    with pytest.raises(ValueError, match="warped: one per registration"):
        CategoryPlanner(HAND, grasps, regs, cloud=cloud, rule=task_rule("mug", "handle"), warped=[shape, shape],
                        settings=CategorySettings(method="warped"))


def test_a_warped_models_lift_pieces_are_its_own_moved_by_the_warp():
    """mug/1 warped onto its own 1.1x copy: the lift test's convex pieces of the warped model are
    mug/1's pieces scaled by 1.1 (the scale within 2%, every point within 12 mm: CPD lets points slide
    along the surface), so the lift test sees the warped shape without decomposing it again."""
    from bayesgrasp.decomposition import convex_decomposition
    from bayesgrasp.objects import load_object
    from bayesgrasp.vision import model_samples

    m = load_object(MUG)
    T = placed(0.3, (0.02, -0.01, 0.0))
    P, _ = model_samples((1.1 * m.vertices, m.faces), samples=2500, seed=4)
    planner = CategoryPlanner(HAND, [TaskGrasp(model=MUG, task="handle", pose=HANDLE, spread=0.0, epsilon=0.2,
                                               lifted=True)],
                              [RegistrationResult.known(MUG, T, phi=1.0)], cloud=P @ T[:3, :3].T + T[:3, 3],
                              rule=task_rule("mug", "handle"), settings=CategorySettings(method="warped"), seed=1)
    (shape,) = planner.warped_models()
    own = convex_decomposition(m.vertices, m.faces, name=m.name)
    assert callable(shape.convex_pieces)                # made when a lift test first needs them
    pieces = shape.lift_pieces()
    assert len(pieces) == len(own)
    W, O = np.concatenate(pieces), np.concatenate(own)
    scale = float(np.sum(W * O) / np.sum(O * O))                  # least squares W ~ scale * O
    assert scale == pytest.approx(1.1, rel=0.02)
    assert np.linalg.norm(W - 1.1 * O, axis=1).max() < 0.012       # CPD lets points slide along the surface
    T2 = placed(1.0, (0.1, 0.2, 0.0))
    moved = shape.transformed(T2).lift_pieces()                  # a moved copy moves them
    np.testing.assert_allclose(np.concatenate(moved), W @ T2[:3, :3].T + T2[:3, 3], atol=1e-12)


def test_the_warps_weigh_by_how_well_each_fits_the_view():
    """Two models registered on a view of the first stretched: each model's weight is phi times
    exp(-(r - min r) / scale) of its warp's residual r, normalised; the better fit weighs more."""
    S = _stretched(sx=1.15)
    T = placed(0.2, (0.0, 0.0, 0.0))
    from bayesgrasp.vision import model_samples
    P, _ = model_samples(S, samples=2000, seed=5)
    regs = [RegistrationResult.known(MUG, T, phi=0.5), RegistrationResult.known("mug/4", T, phi=0.5)]
    planner = CategoryPlanner(HAND, [TaskGrasp(model=MUG, task="handle", pose=HANDLE, spread=0.0, epsilon=0.2,
                                               lifted=True)], regs, cloud=P @ T[:3, :3].T + T[:3, 3],
                              rule=task_rule("mug", "handle"), settings=CategorySettings(method="warped"), seed=1)
    r = np.array([m.params["warp_residual"] for m in planner.warped_models()])
    w = planner.warp_weights()
    expected = 0.5 * np.exp(-(r - r.min()) / planner.settings.warp_residual_scale)
    np.testing.assert_allclose(w, expected / expected.sum())
    assert all(callable(m.convex_pieces) for m in planner.warped_models())   # no lift test: not decomposed
    assert w[np.argmin(r)] > w[np.argmax(r)] or r[0] == r[1]
    with pytest.raises(ValueError, match="warp_residual_scale"):
        CategorySettings(method="warped", warp_residual_scale=0.0)


def test_the_lift_test_takes_a_models_own_pieces_without_decomposing(monkeypatch):
    """An ObjectModel given convex pieces (here one: its hull's points) is lift-tested on those: the
    decomposition is never called and the tester holds exactly that one piece."""
    from bayesgrasp import physics
    from bayesgrasp.objects import load_object
    from bayesgrasp.world import World

    m = load_object(MUG)
    hulled = m.transformed(np.eye(4))
    hulled.convex_pieces = [m.vertices.copy()]

    def refuse(*a, **k):
        raise AssertionError("decomposed although the model has its own pieces")
    monkeypatch.setattr(physics, "convex_decomposition", refuse)
    tester = World.single(hulled, pose=(0.0, 0.0, 0.0), hand=HAND).lift_tester()
    assert tester.concave and tester.num_pieces == 1


def test_the_top_grasp_check_on_a_given_shape_closes_on_that_shape_at_the_models_pose():
    """check_top_grasps(shapes=[S]): the parts each top grasp touches are those on S itself placed
    at the belief's planar pose (S keeps the model's xy origin); the task term "warped" of the
    fusion planner uses it with the models warped onto the view."""
    from bayesgrasp.belief import relative_planar_pose
    from bayesgrasp.planners.part_check import check_top_grasps
    from bayesgrasp.world import World

    S = _stretched(sx=1.25)
    pose = np.array([0.03, -0.02, 0.9])
    G = np.array([[pose[0] + dx, pose[1] + dy, yaw] for dx in (-0.03, 0.0, 0.03) for dy in (-0.01, 0.01)
                  for yaw in (0.0, 1.2)])
    check = check_top_grasps(HAND, task_rule("mug", "top"), G, [MUG], pose[None], [1.0], 0.0, resolve=False,
                             shapes=[S])
    direct = World.single(S, pose=(0.0, 0.0, 0.0), hand=HAND, keep_origin=True)
    b = direct.grasp_batch(relative_planar_pose(G, pose[None, :]), spread=0.0)
    for k in range(len(G)):
        lo, hi = b.contacts.offsets[k], b.contacts.offsets[k + 1]
        assert sorted(check.parts[k][0]) == sorted(p for p in b.contact_part[lo:hi] if p is not None)
    assert any(check.parts[k][0] for k in range(len(G)))
    plain = check_top_grasps(HAND, task_rule("mug", "top"), G, [MUG], pose[None], [1.0], 0.0, resolve=False)
    assert [sorted(p[0]) for p in plain.parts] != [sorted(p[0]) for p in check.parts]   # the shape mattered
    with pytest.raises(ValueError, match="shapes: one per model"):
        check_top_grasps(HAND, task_rule("mug", "top"), G, [MUG], pose[None], [1.0], 0.0, shapes=[S, S])
