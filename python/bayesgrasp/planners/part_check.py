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
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..hand import Hand
from ..models.tasks import TaskRule


@dataclass(frozen=True)
class PartCheck:
    """Per candidate (rows) and model (columns): ``rule_ok`` and ``held``; ``weights`` (M,) the
    models' normalised weights; ``parts`` the contacts' parts per candidate and model."""

    rule_ok: np.ndarray
    held: np.ndarray
    weights: np.ndarray
    parts: list

    @property
    def p_rule(self) -> np.ndarray:
        """P(rule | A) per candidate."""
        return self.rule_ok.astype(float) @ self.weights

    @property
    def p_success(self) -> np.ndarray:
        """P(rule, held | A) per candidate."""
        return (self.rule_ok & self.held).astype(float) @ self.weights


def choose(p_success, J, tiebreak: float = 0.1, product: bool = False) -> int:
    """The part-aware choice: among candidates with P(rule, held | A) > 0 the one maximising
    P + tiebreak * J / max J (``product``: P * J, a third factor beside Eq. 4.6's two); when none
    passes, the one of highest J. So a candidate the part check rejects on every model is never
    chosen while one that passes exists."""
    p, J = np.asarray(p_success, float), np.asarray(J, float)
    top = J.max() if len(J) and J.max() > 0 else 1.0
    passing = p * J / top if product else p + tiebreak * J / top
    return int(np.argmax(np.where(p > 0, 2.0 + passing, J / top)))


_WORLDS: dict = {}


def model_world(model: str, hand: Hand, table: bool):
    """A world holding training model ``model`` at its own frame (built once per process and hand)."""
    from ..world import World

    key = (model, hand.name, id(hand.core), bool(table))
    if key not in _WORLDS:
        if len(_WORLDS) >= 64:
            _WORLDS.clear()
        _WORLDS[key] = World.single(model, pose=(0.0, 0.0, 0.0), hand=hand, table=table)
    return _WORLDS[key]


def rolls_of(poses: np.ndarray) -> np.ndarray:
    """The roll of each hand pose about its approach (the convention of Hand.approach_pose)."""
    out = np.empty(len(poses))
    for k, A in enumerate(poses):
        d = A[:3, 2]
        x0 = Hand.approach_pose(d, 0.0, A[:3, 3])[:3, 0]
        out[k] = np.arctan2(np.cross(x0, A[:3, 0]) @ (-d), x0 @ A[:3, 0])
    return out


def _grasp_parts(batch, k: int) -> list:
    lo, hi = batch.contacts.offsets[k], batch.contacts.offsets[k + 1]
    if batch.contact_part is None:
        return []
    return [p for p in batch.contact_part[lo:hi] if p is not None]


def check_on_model(world, rule: TaskRule, poses: np.ndarray, spreads: np.ndarray, threads: int = 1):
    """``poses`` (K, 4, 4) in the model's frame with their ``spreads`` (K,): (rule_ok (K,), held
    (K,), parts per candidate) of the approach along each pose closed on ``world``'s model."""
    K = len(poses)
    rule_ok, held, parts = np.zeros(K, bool), np.zeros(K, bool), [[] for _ in range(K)]
    # a target under the table (in the model's frame) is no grasp there; the world would refuse it
    feasible = rule.approach_ok(poses[:, :3, 2]) & ((poses[:, 2, 3] >= 0.0) | (not rule.table))
    rolls = rolls_of(poses)
    for s in np.unique(spreads):
        idx = np.flatnonzero((spreads == s) & feasible)
        if not len(idx):
            continue
        b = world.approach_batch(poses[idx, :3, 2], poses[idx, :3, 3], rolls[idx], spread=float(s),
                                 frame="world", threads=threads)
        start = np.asarray(b.collision_at_start, bool)
        table = np.asarray(b.stopped_by_table, bool)
        for j, k in enumerate(idx):
            parts[k] = _grasp_parts(b, j)
            rule_ok[k] = bool(not start[j] and not table[j] and rule.contacts_ok(parts[k]))
            held[k] = bool(b.epsilon[j] > 0.0)
    return rule_ok, held, parts


def check_candidates(hand: Hand, rule: TaskRule, poses, spreads, registrations: Sequence, weights,
                     threads: int = 1) -> PartCheck:
    """Every candidate ``poses`` (K, 4, 4, scene frame) closed on every registered model with
    weight > 0 (the others count 0): a :class:`PartCheck`."""
    A = np.asarray(poses, float).reshape(-1, 4, 4)
    S = np.broadcast_to(np.asarray(spreads, float), (len(A),))
    w = np.asarray(weights, float)
    if len(w) != len(registrations):
        raise ValueError(f"weights: one per registration ({len(registrations)}), got {len(w)}")
    M = len(registrations)
    rule_ok, held = np.zeros((len(A), M), bool), np.zeros((len(A), M), bool)
    parts = [[[] for _ in range(M)] for _ in range(len(A))]
    for i, reg in enumerate(registrations):
        if w[i] <= 0 or not reg.success or not len(A):
            continue
        local = np.linalg.inv(np.asarray(reg.transform, float)) @ A
        world = model_world(reg.model, hand, bool(rule.table))
        r, h, p = check_on_model(world, rule, local, S, threads)
        rule_ok[:, i], held[:, i] = r, h
        for k in range(len(A)):
            parts[k][i] = p[k]
    return PartCheck(rule_ok, held, w, parts)


def check_top_grasps(hand: Hand, rule: TaskRule, grasps, names: Sequence[str], poses, weights,
                     spread: float, threads: int = 1) -> PartCheck:
    """Planar top grasps ``grasps`` (K, 3: x, y, yaw, world) closed on every model ``names[i]`` of
    weight > 0 placed at its planar pose ``poses[i]`` (x, y, yaw): a :class:`PartCheck` (the
    vision-then-touch belief's version of :func:`check_candidates`)."""
    from ..belief import relative_planar_pose

    G = np.atleast_2d(np.asarray(grasps, float))
    P = np.atleast_2d(np.asarray(poses, float))
    w = np.asarray(weights, float)
    if not (len(names) == len(P) == len(w)):
        raise ValueError(f"names, poses, weights: one of each per model, got {len(names)}, {len(P)}, {len(w)}")
    M = len(names)
    rule_ok, held = np.zeros((len(G), M), bool), np.zeros((len(G), M), bool)
    parts = [[[] for _ in range(M)] for _ in range(len(G))]
    from_above = bool(rule.approach_ok(np.array([[0.0, 0.0, -1.0]]))[0])
    for i, name in enumerate(names):
        if w[i] <= 0 or not len(G):
            continue
        b = model_world(name, hand, bool(rule.table)).grasp_batch(relative_planar_pose(G, P[i][None, :]),
                                                                   spread=spread, threads=threads)
        start, table = np.asarray(b.collision_at_start, bool), np.asarray(b.stopped_by_table, bool)
        for k in range(len(G)):
            parts[k][i] = _grasp_parts(b, k)
            rule_ok[k, i] = from_above and not start[k] and not table[k] and rule.contacts_ok(parts[k][i])
            held[k, i] = bool(b.epsilon[k] > 0.0)
    return PartCheck(rule_ok, held, w, parts)
