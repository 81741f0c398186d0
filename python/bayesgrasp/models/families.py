"""Grasp families: how a planner's action (x, y, yaw) in the world becomes a grasp on the object.

Every family's action is three numbers in the world, and its relative grasp - the action in the
object's frame, R(-o_yaw)(a_xy - o_xy), a_yaw - o_yaw - is three numbers too, so the belief,
the model tables and the planners' searches are the same for every family:

* ``top`` (the thesis's): the palm-down hand at (x, y) with yaw descends along -z to the first
  contact and closes.
* ``side``: the hand moves horizontally along the azimuth yaw, on the line through (x, y) at a
  height h above the table, with a roll r about its approach axis, to the first contact, and
  closes. Only the line matters (the hand starts before the object whatever the point on it), so
  the models take the line's relative azimuth a and signed offset d = cos(a) y - sin(a) x from the
  object's origin. The height and the roll are fixed per object and hand, chosen with the finger
  spread by a pilot (:func:`bayesgrasp.models.training.choose_variant`) from
  SIDE_HEIGHT_FRACTIONS x SIDE_ROLLS.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The grasp families, in the order planners try them.
FAMILIES = ("top", "side")

#: Side grasps: candidate heights (fractions of the object's height above the table) and rolls (rad).
SIDE_HEIGHT_FRACTIONS = (0.5, 0.7, 0.85)
SIDE_ROLLS = (0.0, float(np.pi / 2))


def parse_families(text) -> tuple:
    """"top", "side", "top,side" (or a sequence of names) -> a tuple of family names in
    :data:`FAMILIES` order; anything else is a ValueError naming ``families``."""
    names = [s.strip() for s in text.split(",")] if isinstance(text, str) else [str(s) for s in text]
    bad = [n for n in names if n not in FAMILIES]
    if bad or not names:
        raise ValueError(f"families: a comma-separated subset of {', '.join(FAMILIES)}; got {text!r}")
    return tuple(f for f in FAMILIES if f in names)


@dataclass(frozen=True)
class Variant:
    """One family at fixed hand settings: the spread (rad) and, for side grasps, the height (m
    above the table) and the roll (rad)."""

    family: str = "top"
    spread: float = float(np.pi / 2)
    height: float = 0.0
    roll: float = 0.0

    def __post_init__(self):
        if self.family not in FAMILIES:
            raise ValueError(f"family: one of {', '.join(FAMILIES)}; got {self.family!r}")

    def features(self, rel) -> np.ndarray:
        """(..., 3) relative grasps -> GP inputs: top (x, y, cos yaw, sin yaw); side (d, cos a,
        sin a) with d the approach line's signed offset from the object's origin."""
        rel = np.asarray(rel, dtype=float)
        c, s = np.cos(rel[..., 2:3]), np.sin(rel[..., 2:3])
        if self.family == "top":
            return np.concatenate([rel[..., :2], c, s], axis=-1)
        d = c * rel[..., 1:2] - s * rel[..., 0:1]
        return np.concatenate([d, c, s], axis=-1)

    @property
    def n_features(self) -> int:
        return 4 if self.family == "top" else 3

    def sample(self, rng: np.random.Generator, n: int, box) -> np.ndarray:
        """n random relative grasps: top - x, y uniform in the box ((2, 2) lows, highs), yaw
        uniform; side - azimuth uniform, the line's offset uniform within the box's half-diagonal
        (the point on the line nearest the origin)."""
        box = np.asarray(box, dtype=float)
        if self.family == "top":
            return np.column_stack([rng.uniform(box[0, 0], box[1, 0], n), rng.uniform(box[0, 1], box[1, 1], n),
                                    rng.uniform(-np.pi, np.pi, n)])
        r = 0.5 * float(np.hypot(*(box[1] - box[0])))
        a = rng.uniform(-np.pi, np.pi, n)
        d = rng.uniform(-r, r, n)
        return np.column_stack([-d * np.sin(a), d * np.cos(a), a])

    def simulate(self, world, rel, lift: bool = False, threads: int = 0, quality: bool = True):
        """The relative grasps (N, 3) executed in ``world`` (object frame): a WorldGraspBatch."""
        rel = np.atleast_2d(np.asarray(rel, dtype=float))
        if self.family == "top":
            return world.grasp_batch(rel, spread=self.spread, lift=lift, threads=threads, quality=quality)
        directions = np.column_stack([np.cos(rel[:, 2]), np.sin(rel[:, 2]), np.zeros(len(rel))])
        targets = np.column_stack([rel[:, :2], np.full(len(rel), self.height)])
        return world.approach_batch(directions, targets, self.roll, spread=self.spread, lift=lift, threads=threads,
                                    quality=quality)

    def grasp(self, world, rel, lift: bool = False):
        """One relative grasp (3,) executed in ``world``: a WorldGrasp (contacts as records)."""
        x, y, a = (float(v) for v in np.asarray(rel, dtype=float).ravel())
        if self.family == "top":
            return world.grasp(x, y, a, spread=self.spread, lift=lift)
        return world.approach([np.cos(a), np.sin(a), 0.0], [x, y, self.height], self.roll, spread=self.spread,
                              frame="object", lift=lift)

    def as_dict(self) -> dict:
        return {"family": self.family, "spread": self.spread, "height": self.height, "roll": self.roll}
