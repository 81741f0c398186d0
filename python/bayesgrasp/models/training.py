"""Training data for the grasp models, from the simulator: random relative grasps of a family
(:mod:`.families`), their outcomes (joint angles, epsilon, and the lift test), the pilot that
chooses the finger spread (and, for side grasps, the height and roll) and the logistic
calibration of P(S)."""
from __future__ import annotations

import os
import threading
import time
from typing import Callable, Optional

import numpy as np
from scipy.optimize import minimize
from scipy.special import expit

from ..world import World
from .families import SIDE_HEIGHT_FRACTIONS, SIDE_ROLLS, Variant
from .settings import AUTO_SPREADS, SIDE_SPREADS, ModelSettings


def random_relative_grasps(rng: np.random.Generator, n: int, box) -> np.ndarray:
    """n relative top grasps (x, y, yaw): x, y uniform in the box ((2, 2): lows, highs), yaw uniform
    in [-pi, pi)."""
    box = np.asarray(box, dtype=float)
    return np.column_stack([rng.uniform(box[0, 0], box[1, 0], n), rng.uniform(box[0, 1], box[1, 1], n),
                            rng.uniform(-np.pi, np.pi, n)])


def as_variant(settings: ModelSettings, spread) -> Variant:
    """A Variant as given, or the settings' family at the given spread (None: the settings')."""
    if isinstance(spread, Variant):
        return spread
    spread = settings.spread if spread is None else spread
    return Variant(settings.family, float(np.pi / 2 if spread is None else spread))


def simulate_training_data(world: World, settings: ModelSettings, seed_offset: int = 0, n: Optional[int] = None,
                           spread=None):
    """Relative grasps (n, 3), joint angles (n, J) and epsilon (n,) from the simulator, in the
    settings' grasp box for the object (n scaled with the box, see ModelSettings.scaled); grasps
    whose open hand started in collision are dropped. ``spread``: a number (the settings' family)
    or a :class:`Variant`."""
    variant = as_variant(settings, spread)
    rng = np.random.default_rng([settings.seed, seed_offset])
    box = settings.grasp_box(world.object)
    n = settings.scaled(settings.n_samples if n is None else int(n), box)
    rel = variant.sample(rng, n, box)
    b = variant.simulate(world, rel)
    ok = ~np.asarray(b.collision_at_start, dtype=bool)
    return rel[ok], np.asarray(b.joint_angles)[ok], np.asarray(b.epsilon)[ok]


PROGRESS_EVERY = 5.0   # s between progress lines


def lift_chunk() -> int:
    """Lift tests per batch when progress is reported: 4 per core (a test of a concave object
    can take a second, so a batch stays within a few seconds and every core stays busy)."""
    return 4 * (os.cpu_count() or 1)


def lift_tests_in_chunks(lift: Callable[[np.ndarray], np.ndarray], rows: np.ndarray,
                         say: Optional[Callable[[str], None]] = None) -> np.ndarray:
    """(n,) bool: ``lift(rows[s:e])`` (the lift test of each row: a grasp's verdict) over all rows.
    With ``say``, run in batches of :func:`lift_chunk` and report "lift tests: k/n done, about s
    left" at most every PROGRESS_EVERY seconds, also while one batch runs long (the tests release
    the GIL; a grasp that keeps the simulation busy made a batch of 8 silent for 28 s). Each
    grasp's test is independent of its batch, so the verdicts are the same."""
    chunk = lift_chunk()
    if say is None or len(rows) <= chunk:
        return np.asarray(lift(rows), bool)
    out = np.empty(len(rows), dtype=bool)
    start = time.monotonic()
    state = {"done": 0, "last": start}
    lock = threading.Lock()
    stop = threading.Event()

    def report() -> None:
        with lock:
            now, done = time.monotonic(), state["done"]
            if now - state["last"] < PROGRESS_EVERY or done == len(rows):   # all done: the caller says so
                return
            left = f"about {(now - start) / done * (len(rows) - done):.0f} s left" if done else \
                f"{now - start:.0f} s so far"
            say(f"  lift tests: {done}/{len(rows)} done, {left}")
            state["last"] = now

    def heartbeat() -> None:
        while not stop.wait(min(1.0, PROGRESS_EVERY) if PROGRESS_EVERY > 0 else 0.05):
            report()

    watcher = threading.Thread(target=heartbeat, daemon=True)
    watcher.start()
    try:
        for s in range(0, len(rows), chunk):
            e = min(s + chunk, len(rows))
            out[s:e] = np.asarray(lift(rows[s:e]), bool)
            with lock:
                state["done"] = e
            if e < len(rows):
                report()
    finally:
        stop.set()
        watcher.join()
    return out


def lifted_in_chunks(variant: Variant, world: World, rel: np.ndarray,
                     say: Optional[Callable[[str], None]] = None) -> np.ndarray:
    """(n,) bool: the lift test of each relative grasp of ``variant`` (:func:`lift_tests_in_chunks`)."""
    return lift_tests_in_chunks(lambda r: variant.simulate(world, r, lift=True, quality=False).lifted, rel, say)


def lift_outcomes(world: World, rel: np.ndarray, spread, say: Optional[Callable[[str], None]] = None) -> np.ndarray:
    """(n,) bool: each relative grasp (of the family of ``spread``, a number for top grasps or a
    Variant) held in the lift test. A grasp whose hand touches nothing of the object cannot hold
    it and is not simulated. ``say``: progress lines for long batches (:func:`lifted_in_chunks`)."""
    variant = spread if isinstance(spread, Variant) else Variant("top", float(spread))
    rel = np.atleast_2d(np.asarray(rel, dtype=float))
    b = variant.simulate(world, rel, quality=False)
    touches = np.asarray(b.link_contact, dtype=bool).any(axis=1) & ~np.asarray(b.collision_at_start, bool)
    lifted = np.zeros(len(rel), dtype=bool)
    idx = np.flatnonzero(touches)
    if len(idx):
        lifted[idx] = lifted_in_chunks(variant, world, rel[idx], say)
    return lifted


def success_labels(world: World, settings: ModelSettings, rel: np.ndarray, eps: np.ndarray, spread,
                   say: Optional[Callable[[str], None]] = None) -> np.ndarray:
    """S for each grasp under the settings' success criterion (lift test or epsilon); ``say``:
    progress lines for the lift tests."""
    if settings.success == "lift":
        return lift_outcomes(world, rel, as_variant(settings, spread), say)
    return np.asarray(eps) > settings.eps_stable


def hand_spreads(world: World, candidates) -> tuple:
    """The candidate spreads the hand can take (within its spread limits); its default spread
    when none can (a hand without a spread, a gripper's [0, 0])."""
    lo, hi = world.hand.spread_limits
    inside = tuple(sp for sp in candidates if lo - 1e-12 <= sp <= hi + 1e-12)
    return inside or (float(world.hand.core.spread_default),)


def choose_spread(world: World, settings: ModelSettings, say=lambda m: None) -> tuple:
    """The top family's pilot (ModelSettings.spread = None): :func:`choose_variant` over the
    spreads in AUTO_SPREADS the hand can take. Returns (best spread, {degrees: (fraction,
    lifted, tested)})."""
    variants = [Variant("top", sp) for sp in hand_spreads(world, AUTO_SPREADS)]
    best, table = choose_variant(world, settings, variants, say)
    return best.spread, {round(float(np.degrees(v.spread))): row for v, row in zip(variants, table)}


def side_variants(world: World, settings: ModelSettings) -> list:
    """The side family's pilot candidates: SIDE_SPREADS (or the settings' spread) x
    SIDE_HEIGHT_FRACTIONS of the object's height x SIDE_ROLLS."""
    top = float(np.asarray(world.object.bounds, dtype=float)[1, 2])
    spreads = hand_spreads(world, SIDE_SPREADS) if settings.spread is None else (settings.spread,)
    return [Variant("side", sp, round(f * top, 4), r) for sp in spreads for f in SIDE_HEIGHT_FRACTIONS
            for r in SIDE_ROLLS]


def choose_variant(world: World, settings: ModelSettings, variants, say=lambda m: None) -> tuple:
    """The pilot: for each candidate Variant, simulate n_pilot random relative grasps and score
    how often a random grasp succeeds.

    With success "lift": the first n_pilot_lifts collision-free grasps that touch the object are
    lift-tested; score = touching fraction x lifted fraction. With "epsilon": up to n_pilot_lifts
    of the stable grasps are lift-tested; score = stable fraction x lifted fraction. Returns
    (best Variant, [(fraction, lifted, tested) per candidate]); with no grasp lifted by any
    candidate, the one with the largest fraction."""
    table, scores = [], []
    for v in variants:
        rel = v.sample(np.random.default_rng([settings.seed, 7]), settings.n_pilot, settings.grasp_box(world.object))
        b = v.simulate(world, rel, quality=settings.success != "lift")
        free = ~np.asarray(b.collision_at_start, dtype=bool)
        if settings.success == "lift":
            ok = free & np.asarray(b.link_contact, dtype=bool).any(axis=1)
            what = "touch the object"
        else:
            ok = free & (np.asarray(b.epsilon) > settings.eps_stable)
            what = "stable"
        idx = np.flatnonzero(ok)[:settings.n_pilot_lifts]
        lifted = int(np.sum(lifted_in_chunks(v, world, rel[idx], say))) if len(idx) else 0
        frac = float(np.mean(ok))
        table.append((frac, lifted, int(len(idx))))
        scores.append((frac * (lifted / len(idx) if len(idx) else 0.0), frac))
        where = "" if v.family == "top" else f", height {100 * v.height:.1f} cm, roll {np.degrees(v.roll):.0f} deg"
        say(f"  spread {np.degrees(v.spread):3.0f} deg{where}: {100 * frac:.0f}% {what}, "
            f"{lifted}/{len(idx)} of those tested lifted")
    best = max(range(len(scores)), key=lambda i: scores[i])
    return variants[best], table


def fit_calibration(z, stable) -> tuple:
    """Logistic regression P = 1 / (1 + exp(-(a z + b))) of outcomes on scores (maximum likelihood,
    a tiny ridge keeps it finite when the classes separate)."""
    z = np.asarray(z, dtype=float)
    y = np.asarray(stable, dtype=float)

    def nll(p):
        t = p[0] * z + p[1]
        return np.sum(np.logaddexp(0.0, t) - y * t) + 1e-3 * (p[0] ** 2 + p[1] ** 2)

    def grad(p):
        t = p[0] * z + p[1]
        r = expit(t) - y
        return np.array([r @ z, r.sum()]) + 2e-3 * p

    res = minimize(nll, np.array([1.0, 0.0]), jac=grad, method="BFGS")
    return float(res.x[0]), float(res.x[1])
