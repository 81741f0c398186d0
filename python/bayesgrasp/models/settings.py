"""How the grasp models of an object are built: :class:`ModelSettings` (every field is part of
the model cache key) and the constants of the model builder."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

#: Bumped when the simulator or the models change what a cache key means.
CACHE_VERSION = 11  # 11: measured joints and their measurement scale from the hand file (issue 31); 10: the lift test at the hand's strength (issue 30)

#: What a successful grasp is: held in the lift test (the default) or epsilon above eps_stable.
SUCCESS_CRITERIA = ("lift", "epsilon")

#: Where the P(S) calibration's outcomes come from (ModelSettings.calibration).
CALIBRATIONS = ("held_out", "cross_fit")

#: The default grasp box (xy_range None): the object's footprint grown by BOX_MARGIN, and at least
#: +-BOX_MIN_HALF around the object's origin; the sample counts grow with its area relative to
#: (2 BOX_MIN_HALF)^2, at most MAX_SAMPLE_SCALE times (a pitcher's handle reaches 12 cm out).
BOX_MARGIN = 0.01
BOX_MIN_HALF = 0.06
MAX_SAMPLE_SCALE = 2.5

#: Grid nodes of highest P(S) a ModelTable keeps (the planners' PSO seeds).
N_BEST = 64

#: Candidate finger spreads (rad) when ModelSettings.spread is None: top grasps, side grasps.
AUTO_SPREADS = tuple(float(np.radians(d)) for d in (0.0, 30.0, 45.0, 60.0, 90.0))
SIDE_SPREADS = (0.0, float(np.pi / 2))


@dataclass(frozen=True)
class ModelSettings:
    """How the models are built (every field is part of the cache key).

    ``success`` says what the stability model P(S|A,O) learns: "lift" (S = held in the physical
    lift test, as in the thesis's robot experiments) or "epsilon" (S = epsilon > eps_stable, the
    thesis's simulation criterion)."""

    n_samples: int = 2000         # simulated grasps (the measurement model's training set)
    n_inducing: int = 200         # FITC inducing inputs
    xy_range: Optional[float] = None  # relative x, y sampled in +-xy_range (m); None: the object's footprint
    # Finger spread of the grasps (rad), or None (the default): chosen per object from
    # AUTO_SPREADS by a pilot sample, as the spread with the most grasps that are both stable
    # (epsilon) and held in the physical lift test (see training.choose_spread): a spread at which
    # grasps are often stable by epsilon may still rarely hold when lifted.
    spread: Optional[float] = None
    n_pilot: int = 300            # pilot grasps per candidate spread (spread=None)
    n_pilot_lifts: int = 60       # pilot grasps per spread that are lift-tested
    # Epsilon above which a grasp counts as stable: force closure with a margin.
    eps_stable: float = 0.01
    max_iter: int = 150           # hyper-parameter optimisation iterations
    n_calibration: int = 1000     # held-out simulated grasps for the P(S) calibration
    # Where the P(S) calibration's outcomes come from: "held_out" (n_calibration fresh simulated and
    # lift-tested grasps) or "cross_fit" (success "lift" only: the stability model's own labelled
    # grasps, each scored by a GP fitted on the other half of them; no further lift test).
    calibration: str = "held_out"
    seed: int = 0
    success: str = "lift"
    n_lift_samples: int = 1000    # training grasps lift-tested for the stability model (success "lift")
    # The grasp family the models describe (models.families): "top" (the thesis's) or "side".
    family: str = "top"

    def __post_init__(self):
        if self.n_samples < 10:
            raise ValueError(f"n_samples: need at least 10, got {self.n_samples}")
        if self.n_inducing < 1:
            raise ValueError(f"n_inducing: must be >= 1, got {self.n_inducing}")
        if self.xy_range is not None and not (self.xy_range > 0 and np.isfinite(self.xy_range)):
            raise ValueError(f"xy_range: must be positive, got {self.xy_range}")
        if self.spread is not None and not (np.isfinite(self.spread) and 0.0 <= self.spread <= np.pi):
            raise ValueError(f"spread: must be None (choose per object) or in [0, pi], got {self.spread}")
        if self.n_pilot < 10 or self.n_pilot_lifts < 1:
            raise ValueError("n_pilot: need at least 10 grasps and n_pilot_lifts at least 1")
        if self.success not in SUCCESS_CRITERIA:
            raise ValueError(f"success: one of {', '.join(SUCCESS_CRITERIA)}; got {self.success!r}")
        from .families import FAMILIES
        if self.family not in FAMILIES:
            raise ValueError(f"family: one of {', '.join(FAMILIES)}; got {self.family!r}")
        if self.calibration not in CALIBRATIONS:
            raise ValueError(f"calibration: one of {', '.join(CALIBRATIONS)}; got {self.calibration!r}")
        if self.calibration == "cross_fit" and self.success != "lift":
            raise ValueError("calibration: 'cross_fit' needs success 'lift' (it reuses the lift-tested training grasps)")
        if not 10 <= self.n_lift_samples:
            raise ValueError(f"n_lift_samples: need at least 10, got {self.n_lift_samples}")

    def as_stored(self) -> dict:
        """The fields as stored in cache keys and beside results: all of them, except ``calibration``
        at its default (entries and results made before it existed keep their identity)."""
        from dataclasses import asdict

        fields = asdict(self)
        if fields["calibration"] == "held_out":
            del fields["calibration"]
        return fields

    def grasp_box(self, obj) -> np.ndarray:
        """(2, 2) rows (x_lo, y_lo), (x_hi, y_hi): where relative top grasps are sampled for ``obj``
        (an ObjectModel): +-xy_range, or (None) the object's footprint grown by BOX_MARGIN and
        containing +-BOX_MIN_HALF."""
        if self.xy_range is not None:
            return np.array([[-self.xy_range, -self.xy_range], [self.xy_range, self.xy_range]])
        b = np.asarray(obj.bounds, dtype=float)[:, :2]
        return np.array([np.minimum(b[0] - BOX_MARGIN, -BOX_MIN_HALF), np.maximum(b[1] + BOX_MARGIN, BOX_MIN_HALF)])

    def scaled(self, n: int, box) -> int:
        """A sample count for the box: n for a fixed xy_range, else n times the box's area relative
        to the default square (at least 1, at most MAX_SAMPLE_SCALE)."""
        if self.xy_range is not None:
            return int(n)
        area = float(np.prod(np.asarray(box)[1] - np.asarray(box)[0]))
        return int(round(n * min(MAX_SAMPLE_SCALE, max(1.0, area / (2 * BOX_MIN_HALF) ** 2))))

    @property
    def stability_threshold(self) -> float:
        """The level of the stability GP's latent value above which a grasp counts as stable: 0.5
        for the lift outcome (0/1), eps_stable for epsilon."""
        return 0.5 if self.success == "lift" else self.eps_stable
