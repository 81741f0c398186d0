"""Where the fingers land: a candidate task grasp closed on every registered training model.

Eq. 4.1 scores how close a hand pose is to the demonstrated grasps carried over by registration;
it does not look at where this hand pose puts the fingers. Each training model carries part labels
per triangle and each registration T_i places model i in the scene, so a candidate hand pose A can
be tried on model i: the open hand approaches along A's direction through A's position with A's
roll (as the executed grasp does), closes, and the contacts' parts are read. On model i:

    rule_i(A) = the approach direction and the contacts obey the task's rule
    held_i(A) = the closed hand is in force closure on the model (epsilon > 0)

and over the models, with their normalised registration weights w_i (phi(delta_i)):

    P(rule | A)         = sum_i w_i 1[rule_i(A)]
    P(rule, held | A)   = sum_i w_i 1[rule_i(A) and held_i(A)]

Model i is closed in its own frame (the candidate mapped by T_i^-1), so a registration that tilts
the model is followed exactly; the table is the model frame's z = 0 plane when the rule has one.

Two steps, because epsilon (a wrench-space hull per grasp) costs far more than the closing: every
candidate is closed and its rule read (:func:`check_candidates`); held is then computed only where
needed (:meth:`PartCheck.resolve`): :func:`choose_lazily` visits the candidates in the order of an
upper bound of their score (P(rule, held) <= P(rule)) and stops once no unvisited one can win, so it
returns what :func:`choose` would return with held known everywhere.

Force closure does not see a grasp that slips when lifted (a mug taken from the top by its rim).
Where the models are shapes warped onto the view, :func:`choose_by_lift` lets the lift test on
them decide among the few best candidates that pass:

    P(rule, held, lifted | A) = sum_i w_i 1[rule_i(A) and held_i(A) and lifted_i(A)]
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from ..hand import Hand
from ..models.tasks import TaskRule


@dataclass
class PartCheck:
    """Per candidate (rows) and model (columns): ``rule_ok`` (the share of the model's placements
    on which the rule holds: 0 or 1 without jitter) and ``held`` (valid on the rows ``known``); ``weights`` (M,) the models' normalised weights; ``parts`` the contacts' parts per
    candidate and model; ``held_of(rows)`` -> (len(rows), M) held for rows not known yet."""

    rule_ok: np.ndarray
    held: np.ndarray
    weights: np.ndarray
    parts: list
    known: np.ndarray = None
    held_of: Callable = field(default=None, repr=False)
    lifted_of: Callable = field(default=None, repr=False)

    def __post_init__(self):
        if self.known is None:
            self.known = np.ones(len(self.rule_ok), bool)

    @property
    def p_rule(self) -> np.ndarray:
        """P(rule | A) per candidate."""
        return np.asarray(self.rule_ok, float) @ self.weights

    @property
    def p_success(self) -> np.ndarray:
        """P(rule, held | A) per candidate (NaN where held is not known yet)."""
        p = (np.asarray(self.rule_ok, float) * self.held) @ self.weights
        return np.where(self.known, p, np.nan)

    def p_lifted(self, rows) -> np.ndarray:
        """P(rule, held, lifted | A) for candidates ``rows`` (held resolved first): the lift test
        run on each model where the rule holds and the hand is in force closure."""
        rows = np.asarray(rows, np.int64).ravel()
        self.resolve(rows)
        ok = np.asarray(self.rule_ok, float)[rows] * self.held[rows]
        return (ok * self.lifted_of(rows, ok > 0)) @ self.weights

    def resolve(self, rows=None) -> "PartCheck":
        """Compute held for ``rows`` (default: all) where not known yet; returns self."""
        rows = np.arange(len(self.rule_ok)) if rows is None else np.asarray(rows, np.int64).ravel()
        todo = rows[~self.known[rows]]
        if len(todo):
            self.held[todo] = self.held_of(todo)
            self.known[todo] = True
        return self


def best_passing(check: PartCheck, J, n: int, tiebreak: float = 0.1, batch: int = 4) -> np.ndarray:
    """Up to ``n`` candidates that pass on some model (P(rule, held | A) > 0), best first by
    :func:`choose`'s score, held computed only as far as needed (the bound of :func:`choose_lazily`)."""
    J = np.asarray(J, float)
    top = _top(J)
    bound = _scores(check.p_rule, J, top, tiebreak, False)
    order = [int(k) for k in np.argsort(-bound, kind="stable") if check.p_rule[k] > 0]
    for start in range(0, len(order), batch):
        known = np.flatnonzero(check.known & (np.nan_to_num(check.p_success) > 0))
        if len(known) >= n:
            s = np.sort(_scores(check.p_success[known], J[known], top, tiebreak, False))[::-1]
            if s[n - 1] >= bound[order[start]]:
                break
        check.resolve(order[start:start + batch])
    known = np.flatnonzero(check.known & (np.nan_to_num(check.p_success) > 0))
    s = _scores(check.p_success[known], J[known], top, tiebreak, False)
    return known[np.argsort(-s, kind="stable")[:n]]


def choose_by_lift(check: PartCheck, J, n: int, tiebreak: float = 0.1) -> tuple:
    """The lift test decides among the ``n`` best passing candidates (:func:`best_passing`): the
    one of highest P(rule, held, lifted | A) + tiebreak * J / max J, a grasp in force closure may
    still slip when lifted. Returns (candidate or None when none of them lifts on any model, the
    number of candidates lift-tested, P(rule, held, lifted) of the choice)."""
    J = np.asarray(J, float)
    rows = best_passing(check, J, n, tiebreak)
    if not len(rows):
        return None, 0, 0.0
    p = check.p_lifted(rows)
    if p.max() <= 0:
        return None, len(rows), 0.0
    top = _top(J)
    j = int(np.argmax(np.where(p > 0, p + tiebreak * J[rows] / top, -np.inf)))
    return int(rows[j]), len(rows), float(p[j])


def _top(J: np.ndarray) -> float:
    """max J, the normaliser of the tie-break (1 when no J is positive)."""
    return float(J.max()) if len(J) and J.max() > 0 else 1.0


def _scores(p, J, top: float, tiebreak: float, product: bool) -> np.ndarray:
    passing = p * J / top if product else p + tiebreak * J / top
    return np.where(p > 0, 2.0 + passing, J / top)


def choose(p_success, J, tiebreak: float = 0.1, product: bool = False) -> int:
    """The part-aware choice: among candidates with P(rule, held | A) > 0 the one maximising
    P + tiebreak * J / max J (``product``: P * J, a third factor beside Eq. 4.6's two); when none
    passes, the one of highest J. So a candidate the part check rejects on every model is never
    chosen while one that passes exists."""
    p, J = np.asarray(p_success, float), np.asarray(J, float)
    top = _top(J)
    return int(np.argmax(_scores(p, J, top, tiebreak, product)))


def choose_lazily(check: PartCheck, J, tiebreak: float = 0.1, product: bool = False, batch: int = 4) -> int:
    """:func:`choose` on ``check``'s P(rule, held | A), computing held only for the candidates that
    could still win (branch and bound on P(rule, held) <= P(rule)); the same answer, ties included."""
    J = np.asarray(J, float)
    top = _top(J)
    bound = _scores(check.p_rule, J, top, tiebreak, product)
    order = np.argsort(-bound, kind="stable")
    for start in range(0, len(order), batch):
        nxt = order[start]
        if check.known.all():
            break
        known = np.flatnonzero(check.known)
        if len(known) and _scores(check.p_success[known], J[known], top, tiebreak, product).max() > bound[nxt]:
            break
        check.resolve(order[start:start + batch])
    known = np.flatnonzero(check.known)
    s = np.full(len(J), -np.inf)
    s[known] = _scores(check.p_success[known], J[known], top, tiebreak, product)
    return int(np.argmax(s))


_WORLDS: dict = {}


def model_world(model: str, hand: Hand, table: bool):
    """A world holding training model ``model`` at its own frame (built once per process and hand
    name: a hand is known by its name, as in the hand files)."""
    from ..world import World

    key = (model, hand.name, bool(table))
    if key not in _WORLDS:
        if len(_WORLDS) >= 64:
            _WORLDS.clear()
        _WORLDS[key] = World.single(model, pose=(0.0, 0.0, 0.0), hand=hand, table=table)
    return _WORLDS[key]


def _grasp_parts(batch, k: int) -> list:
    lo, hi = batch.contacts.offsets[k], batch.contacts.offsets[k + 1]
    if batch.contact_part is None:
        return []
    return [p for p in batch.contact_part[lo:hi] if p is not None]


@dataclass
class _Closings:
    """One model's closings: per candidate its batch and row (-1: not closed, held is False)."""

    world: object
    batches: list
    where: np.ndarray      # (K, 2): batch index, row

    def _per_batch(self, rows, verdict: Callable) -> np.ndarray:
        """``verdict(batch, batch rows)`` -> bool per row, gathered for the candidates ``rows``
        (False where a candidate was not closed)."""
        out = np.zeros(len(rows), bool)
        for j, b in enumerate(self.batches):
            sel = np.flatnonzero(self.where[rows, 0] == j)
            if len(sel):
                out[sel] = verdict(b, self.where[rows[sel], 1])
        return out

    def held(self, rows, threads: int = 1) -> np.ndarray:
        return self._per_batch(rows, lambda b, r: self.world.epsilon_of(b, r, threads) > 0.0)

    def lifted(self, rows, threads: int = 1) -> np.ndarray:
        """The lift test of the closed hands ``rows`` on this model (False where not closed or
        started in collision)."""
        def lift(b, r):
            test = self.world.lift_tester().run_batch(b.hand_pose[r], b.joint_angles[r], threads=threads)
            return np.asarray(test.lifted, bool) & ~np.asarray(b.collision_at_start, bool)[r]
        return self._per_batch(rows, lift)


def _read(rule: TaskRule, batches, where, K: int, from_ok) -> tuple:
    rule_ok, parts = np.zeros(K, bool), [[] for _ in range(K)]
    for k in range(K):
        j, row = where[k]
        if j < 0:
            continue
        b = batches[j]
        parts[k] = _grasp_parts(b, row)
        rule_ok[k] = bool(from_ok[k] and not b.collision_at_start[row] and not b.stopped_by_table[row]
                          and rule.contacts_ok(parts[k]))
    return rule_ok, parts


def close_on_model(world, rule: TaskRule, poses: np.ndarray, spreads: np.ndarray, threads: int = 1):
    """``poses`` (K, 4, 4) in the model's frame with their ``spreads`` (K,): (rule_ok (K,), parts
    per candidate, the closings) of the approach along each pose closed on ``world``'s model."""
    K = len(poses)
    # a direction the rule forbids, or a target under the table (in the model's frame), is not closed
    feasible = rule.approach_ok(poses[:, :3, 2]) & ((poses[:, 2, 3] >= 0.0) | (not rule.table))
    rolls = np.array([Hand.approach_roll(A) for A in poses])
    batches, where = [], np.full((K, 2), -1, np.int64)
    for s in np.unique(spreads):
        idx = np.flatnonzero((spreads == s) & feasible)
        if not len(idx):
            continue
        batches.append(world.approach_batch(poses[idx, :3, 2], poses[idx, :3, 3], rolls[idx], spread=float(s),
                                            frame="world", threads=threads, quality=False))
        where[idx] = np.c_[np.full(len(idx), len(batches) - 1), np.arange(len(idx))]
    rule_ok, parts = _read(rule, batches, where, K, np.ones(K, bool))
    return rule_ok, parts, _Closings(world, batches, where)


def _combine(K: int, M: int, weights, per_model: dict, threads: int, resolve: bool) -> PartCheck:
    """A PartCheck from per-model (rule_ok, parts, closings); held computed now if ``resolve``."""
    rule_ok, parts = np.zeros((K, M)), [[[] for _ in range(M)] for _ in range(K)]
    for i, (r, p, _) in per_model.items():
        rule_ok[:, i] = r
        for k in range(K):
            parts[k][i] = p[k]

    def held_of(rows):
        h = np.zeros((len(rows), M), bool)
        for i, (r, _, closings) in per_model.items():
            need = np.flatnonzero(r[rows] > 0)      # held matters only where the rule holds
            if len(need):
                h[need, i] = closings.held(rows[need], threads)
        return h

    def lifted_of(rows, need):
        lifted = np.zeros((len(rows), M), bool)
        for i, (_, _, closings) in per_model.items():
            sel = np.flatnonzero(need[:, i])
            if len(sel):
                lifted[sel, i] = closings.lifted(rows[sel], threads)
        return lifted

    check = PartCheck(rule_ok, np.zeros((K, M), bool), np.asarray(weights, float), parts, np.zeros(K, bool), held_of,
                      lifted_of)
    return check.resolve() if resolve else check


def _turned(yaw: float) -> np.ndarray:
    T = np.eye(4)
    T[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    return T


def shape_world(shape, hand: Hand, table: bool):
    """(a world holding ``shape``, an ObjectModel in its model's frame, and the 4x4 shift from that
    frame to the world's): the shape keeps its xy origin and rests on the table (its lowest point
    at z = 0), as a warped model whose bottom moved would."""
    from ..world import World

    world = World.single(shape, pose=(0.0, 0.0, 0.0), hand=hand, table=table, keep_origin=True)
    shift = np.eye(4)
    shift[:3, 3] = world.scene.object_offset(0)
    return world, shift


def check_candidates(hand: Hand, rule: TaskRule, poses, spreads, registrations: Sequence, weights,
                     threads: int = 1, resolve: bool = True, jitter_yaw: Sequence[float] = (),
                     shapes: Sequence = None) -> PartCheck:
    """Every candidate ``poses`` (K, 4, 4, scene frame) closed on every registered model with
    weight > 0 (the others count 0): a :class:`PartCheck`; held computed for every candidate unless
    ``resolve`` is False (then :func:`choose_lazily` computes what it needs). Held is only computed
    where the rule holds (elsewhere it does not change P(rule, held) and is left False).

    ``jitter_yaw`` (rad): the model is also closed turned by each of these about its own vertical
    axis (T_i Rz(d)), as a registration that got the yaw slightly wrong would place it; rule_ok is
    then the share of the placements on which the rule holds (held is read at T_i itself).

    ``shapes``: per registration an ObjectModel (in that model's frame) to close on instead of the
    model itself, e.g. the model warped onto the cloud (None entries: the model)."""
    A = np.asarray(poses, float).reshape(-1, 4, 4)
    S = np.broadcast_to(np.asarray(spreads, float), (len(A),))
    w = np.asarray(weights, float)
    if len(w) != len(registrations):
        raise ValueError(f"weights: one per registration ({len(registrations)}), got {len(w)}")
    if shapes is not None and len(shapes) != len(registrations):
        raise ValueError(f"shapes: one per registration ({len(registrations)}) or None, got {len(shapes)}")
    per_model = {}
    for i, reg in enumerate(registrations):
        if w[i] <= 0 or not reg.success or not len(A):
            continue
        shape = None if shapes is None else shapes[i]
        if shape is None:
            world, shift = model_world(reg.model, hand, bool(rule.table)), np.eye(4)
        else:
            world, shift = shape_world(shape, hand, bool(rule.table))
        T = np.asarray(reg.transform, float)
        r, parts, closings = close_on_model(world, rule, shift @ np.linalg.inv(T) @ A, S, threads)
        r = r.astype(float)
        for d in jitter_yaw:
            r += close_on_model(world, rule, shift @ np.linalg.inv(T @ _turned(float(d))) @ A, S, threads)[0]
        per_model[i] = (r / (1 + len(jitter_yaw)), parts, closings)
    return _combine(len(A), len(registrations), w, per_model, threads, resolve)


def check_top_grasps(hand: Hand, rule: TaskRule, grasps, names: Sequence[str], poses, weights,
                     spread: float, threads: int = 1, resolve: bool = True, shapes: Sequence = None) -> PartCheck:
    """Planar top grasps ``grasps`` (K, 3: x, y, yaw, world) closed on every model ``names[i]`` of
    weight > 0 placed at its planar pose ``poses[i]`` (x, y, yaw): a :class:`PartCheck` (the
    vision-then-touch belief's version of :func:`check_candidates`). ``shapes``: per model an
    ObjectModel in its frame to close on instead (a warped model resting on the table; None
    entries: the model)."""
    from ..belief import relative_planar_pose

    G = np.atleast_2d(np.asarray(grasps, float))
    P = np.atleast_2d(np.asarray(poses, float))
    w = np.asarray(weights, float)
    if not (len(names) == len(P) == len(w)):
        raise ValueError(f"names, poses, weights: one of each per model, got {len(names)}, {len(P)}, {len(w)}")
    if shapes is not None and len(shapes) != len(names):
        raise ValueError(f"shapes: one per model ({len(names)}) or None, got {len(shapes)}")
    K = len(G)
    from_above = bool(rule.approach_ok(np.array([[0.0, 0.0, -1.0]]))[0])
    per_model = {}
    for i, name in enumerate(names):
        if w[i] <= 0 or not K:
            continue
        shape = None if shapes is None else shapes[i]
        # a shape keeps the model's xy origin (shape_world): the planar grasps relative to it are the same
        world = model_world(name, hand, bool(rule.table)) if shape is None else shape_world(shape, hand, rule.table)[0]
        b = world.grasp_batch(relative_planar_pose(G, P[i][None, :]), spread=spread, threads=threads, quality=False)
        where = np.c_[np.zeros(K, np.int64), np.arange(K)]
        r, p = _read(rule, [b], where, K, np.full(K, from_above))
        per_model[i] = (r, p, _Closings(world, [b], where))
    return _combine(K, len(names), w, per_model, threads, resolve)
