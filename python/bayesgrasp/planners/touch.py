"""One touch (thesis ch. 2, Pub. I): what a single grasp's contacts and joint angles tell about an
object's pose and size. The C++ core's touch model (``bayesgrasp._core.touch``) and Fig. 2.1's loop on it.

The robot executes a grasp (a palm-down top grasp: descend to the first contact, close), reads a
0/1 contact flag per link, the joint angles and the hand pose at which it closed, and searches for
the object state (x, y, yaw[, scale]) whose re-simulated grasp reproduces those readings::

    model = TouchModel("mug")                                   # the robot's internal model
    world = touch_world("mug", (0.01, 0.0, 0.3))               # the "real" object
    grasp = top_grasp(0.0, 0.0, 0.2)                            # what the robot did ...
    readings = read(world, grasp)                               # ... and read
    r = model.estimate(grasp, readings, initial=(0.0, 0.0, 0.2), optimizer="pso")
    r.state, r.fitness, r.trace_fitness

The fitness (touch/fitness.hpp) is f = sum_j ((q_j - q_j^m) / 0.05 rad)^2 + (number of links whose
contact flag differs) + ((z - z^m) / 5 mm)^2, z the hand height where the descent stopped; the
continuous variant (``contact_term="surface"``) replaces the flag count by how far the links that
touched are from the candidate's surface (1 per centimetre, capped at 1) plus 1 per link that did
not touch but would penetrate the candidate.

Fig. 2.1's loop (:class:`TouchPlanner`, the package's planner interface, :mod:`.protocol`):
initial guess -> plan -> trial -> update the model -> re-plan. The belief is a point estimate of
the object (x, y, yaw, scale). Without grasp models the plan is the touch: a palm-down top grasp at
the estimated object centre (the origin of the object's frame: the centre of its xy bounding box),
the hand's x axis along the object's estimated x axis, at the hand's default spread. With grasp
models it is the models' most stable relative grasp placed at the estimate, the grasp a robot
would try on its guess, so the exploration is a by-product of a grasp attempt, as in the thesis.
Either way ``observe`` replaces the estimate by the state whose re-simulated grasp best reproduces
the readings::

    planner = TouchPlanner("mug", estimate=(0.0, 0.0, 0.3))       # models=...: plan stable grasps
    plan = planner.plan()                         # TouchPlan: .touch (TouchGrasp), .action (x, y, yaw)
    result = planner.observe(plan, readings)      # readings of the executed grasp: an EstimateResult
    planner.belief                                # the estimate (x, y, yaw, scale)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence, Union

import numpy as np

from .. import _core
from ..belief import absolute_planar_pose
from .. import DEFAULT_HAND
from ..hand import Hand
from ..models import GraspModels
from ..objects import ObjectModel, Scene, load_object
from ..sim import GraspSimulator

_t = _core.touch
TouchGrasp, TouchReadings, TouchPredictions = _t.TouchGrasp, _t.TouchReadings, _t.TouchPredictions
FitnessOptions, FitnessTerms, SearchBox = _t.FitnessOptions, _t.FitnessTerms, _t.SearchBox
EstimateOptions, EstimateResult, EstimateStatus = _t.EstimateOptions, _t.EstimateResult, _t.EstimateStatus
TouchModelOptions, minimum_budget = _t.TouchModelOptions, _t.minimum_budget

__all__ = ["OPTIMIZERS", "UNKNOWNS", "CONTACT_TERMS", "TouchModel", "TouchGrasp", "TouchReadings", "EstimateOptions",
           "EstimateResult", "EstimateStatus", "FitnessOptions", "SearchBox", "canonical_object", "estimate_options",
           "minimum_budget", "orientation_error", "read", "scaled_object", "symmetry_order", "top_grasp",
           "touch_world", "TouchPlan", "TouchPlanner", "TouchSettings"]

#: Optimisers by name (the CLI's and the experiment's): the four of the thesis and a trust region.
OPTIMIZERS = {"descent": _t.Optimizer.descent, "sa": _t.Optimizer.annealing, "pso": _t.Optimizer.pso,
              "firefly": _t.Optimizer.firefly, "trust_region": _t.Optimizer.trust_region}
#: Pub. I's cases: 3 DoF, 4 DoF (plus a uniform scale), the orientation with the position given.
UNKNOWNS = {"pose": _t.Unknowns.pose, "pose_and_scale": _t.Unknowns.pose_and_scale,
            "orientation": _t.Unknowns.orientation}
CONTACT_TERMS = {"flags": _t.ContactTerm.flags, "surface": _t.ContactTerm.surface}


def _choice(table: dict, value, what: str):
    if value not in table:
        raise ValueError(f"{what}: one of {', '.join(table)}; got {value!r}")
    return table[value]


def canonical_object(obj: Union[str, ObjectModel]) -> ObjectModel:
    """The object in its own frame as a :class:`~bayesgrasp.objects.Scene` places it (xy-box centre on
    the z axis, lowest point at z = 0): the frame of the touch model's states."""
    return Scene.single(obj).canonical_object(0)


def scaled_object(obj: Union[str, ObjectModel], scale: float) -> ObjectModel:
    """The object scaled uniformly by ``scale`` about its frame's origin (it stays on the table)."""
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale: must be positive and finite, got {scale}")
    c = canonical_object(obj)
    return c.transformed(np.diag([scale, scale, scale, 1.0]), name=c.name)


def touch_world(obj: Union[str, ObjectModel], pose: Sequence[float], scale: float = 1.0,
                hand: Union[Hand, str] = DEFAULT_HAND) -> GraspSimulator:
    """The "real" world of a touch: the object (scaled) at planar pose (x, y, yaw), world frame."""
    model = scaled_object(obj, scale) if scale != 1.0 else canonical_object(obj)
    V, F = Scene.single(model, *pose).object_mesh_world(0)
    return GraspSimulator(hand, V, F)


def top_grasp(x: float, y: float, yaw: float, spread: float = 0.0, standoff: float = 0.0) -> TouchGrasp:
    """A palm-down top grasp at world (x, y, yaw): descend to the first contact, close."""
    return TouchGrasp.top(float(x), float(y), float(yaw), float(spread), float(standoff))


def read(world: GraspSimulator, grasp: TouchGrasp) -> TouchReadings:
    """Executes ``grasp`` in ``world`` and returns what the hand read."""
    return TouchReadings.from_grasp(_t.execute(world.core, grasp))


#: The core's defaults (EstimateOptions' own): the one home of every touch-search default.
_CORE = EstimateOptions()


def _name_of(table: dict, value) -> str:
    return next(k for k, v in table.items() if v == value)


def estimate_options(optimizer: Optional[str] = None, unknowns: Optional[str] = None, budget: Optional[int] = None,
                     seed: Optional[int] = None, contact_term: Optional[str] = None,
                     box: Optional[Sequence[float]] = None, population: Optional[int] = None,
                     threads: Optional[int] = None, stop_fitness: Optional[float] = None) -> EstimateOptions:
    """EstimateOptions from names; None keeps the core's default (pso, pose, 2,000 evaluations,
    seed 0, flags, the box (0.03 m, 30 deg, 0.8, 1.2), the optimiser's population, one thread,
    stop_fitness 0). ``box``: (xy m, yaw rad, scale_low, scale_high). ``stop_fitness`` > 0 ends the
    search once a candidate's fitness is below it (0: spend the whole budget)."""
    o = EstimateOptions()
    if optimizer is not None:
        o.optimizer = _choice(OPTIMIZERS, optimizer, "optimizer")
    if unknowns is not None:
        o.unknowns = _choice(UNKNOWNS, unknowns, "unknowns")
    if contact_term is not None:
        o.fitness.contact_term = _choice(CONTACT_TERMS, contact_term, "contact_term")
    for name, value, kind in (("budget", budget, int), ("seed", seed, int), ("population", population, int),
                              ("threads", threads, int), ("stop_fitness", stop_fitness, float)):
        if value is not None:
            setattr(o, name, kind(value))
    if box is not None:
        b = SearchBox()
        b.xy, b.yaw, b.scale_low, b.scale_high = (float(v) for v in box)
        o.box = b
    return o


class TouchModel:
    """The robot's internal model of one object for touches: the core's TouchModel on the object's
    canonical mesh (see :func:`canonical_object`) and the hand."""

    def __init__(self, obj: Union[str, ObjectModel], hand: Union[Hand, str] = DEFAULT_HAND,
                 options: Optional[TouchModelOptions] = None):
        self.object = canonical_object(obj)
        self.hand = hand if isinstance(hand, Hand) else Hand.load(hand)
        self.core = _t.TouchModel(self.hand.core, self.object.vertices, self.object.faces.astype(np.int32),
                                  options or TouchModelOptions())

    def predict(self, grasp: TouchGrasp, states, measured: Optional[TouchReadings] = None,
                threads: int = 1) -> TouchPredictions:
        """Predicted readings at states (N, 3) x, y, yaw or (N, 4) with a scale."""
        return self.core.predict(grasp, np.atleast_2d(np.asarray(states, dtype=float)), measured, int(threads))

    def fitness(self, grasp: TouchGrasp, measured: TouchReadings, states, contact_term: str = "flags",
                options: Optional[FitnessOptions] = None, threads: int = 1) -> FitnessTerms:
        """Pub. I's fitness at states (N, 3) or (N, 4)."""
        o = options or FitnessOptions()
        if options is None:
            o.contact_term = _choice(CONTACT_TERMS, contact_term, "contact_term")
        return self.core.fitness(grasp, measured, np.atleast_2d(np.asarray(states, dtype=float)), o, int(threads))

    def estimate(self, grasp: TouchGrasp, measured: TouchReadings, initial: Sequence[float],
                 options: Optional[EstimateOptions] = None, **names) -> EstimateResult:
        """The estimate from ``initial`` (x, y, yaw[, scale]); options as an EstimateOptions or as
        the names of :func:`estimate_options`."""
        s0 = np.asarray(initial, dtype=float).ravel()
        if s0.shape == (3,):
            s0 = np.append(s0, 1.0)
        if s0.shape != (4,):
            raise ValueError(f"initial: expected (x, y, yaw) or (x, y, yaw, scale), got {np.shape(initial)}")
        return self.core.estimate(grasp, measured, s0, options if options is not None else estimate_options(**names))


def symmetry_order(obj: Union[str, ObjectModel]) -> Optional[int]:
    """How many yaws map the object onto itself: 4 for the cube, None for a body of revolution
    (cylinder, bottle: its orientation is undefined), 1 for anything else (mesh files included)."""
    model = load_object(obj) if isinstance(obj, str) else obj
    kind = (model.params or {}).get("kind")
    if kind == "cube":
        return 4
    if kind in ("cylinder", "bottle"):
        return None
    return 1


def orientation_error(estimate_yaw: float, true_yaw: float, order: Optional[int]) -> Optional[float]:
    """|yaw error| (rad) modulo the object's symmetry (2 pi / order); None when undefined."""
    if order is None:
        return None
    period = 2 * np.pi / order
    d = np.mod(float(estimate_yaw) - float(true_yaw) + period / 2, period) - period / 2
    return float(abs(d))


@dataclass(frozen=True)
class TouchSettings:
    """optimizer: descent, sa, pso, firefly or trust_region; unknowns: pose, pose_and_scale or
    orientation; budget: fitness evaluations; box: the search box around the estimate (xy m, yaw
    rad, scale_low, scale_high); contact_term: flags or surface; spread: of the touch (None: the
    hand's default); threads: C++ threads of the batches; stop_fitness: end the search once a
    candidate reproduces the readings below this fitness (0: spend the budget; 0.003 makes a 3-DoF
    PSO estimate 2.5-4x faster with the same errors, BENCHMARKS.md)."""

    optimizer: str = _name_of(OPTIMIZERS, _CORE.optimizer)
    unknowns: str = _name_of(UNKNOWNS, _CORE.unknowns)
    budget: int = _CORE.budget
    seed: int = _CORE.seed
    box: Sequence[float] = (_CORE.box.xy, _CORE.box.yaw, _CORE.box.scale_low, _CORE.box.scale_high)
    contact_term: str = _name_of(CONTACT_TERMS, _CORE.fitness.contact_term)
    spread: Optional[float] = None
    threads: int = _CORE.threads
    stop_fitness: float = _CORE.stop_fitness

    def options(self) -> EstimateOptions:
        return estimate_options(self.optimizer, self.unknowns, self.budget, self.seed, self.contact_term, self.box,
                                threads=self.threads, stop_fitness=self.stop_fitness)


@dataclass
class TouchPlan:
    """The next grasp: ``touch``, the top grasp the hand executes (a TouchGrasp: descend, close);
    ``action`` its (x, y, yaw) in the world; ``kind`` "touch" (the estimated centre, along the
    estimated yaw) or "stability" (the grasp models' most stable grasp at the estimate)."""

    touch: TouchGrasp
    action: np.ndarray
    kind: str
    estimate: np.ndarray

    def to_dict(self) -> dict:
        return {"kind": self.kind, "action": self.action.tolist(), "spread": float(self.touch.spread),
                "estimate": self.estimate.tolist()}


class TouchPlanner:
    """Fig. 2.1's loop on a point estimate of one object (see the module docstring)."""

    def __init__(self, obj: Union[str, ObjectModel, TouchModel], estimate: Sequence[float],
                 settings: Optional[TouchSettings] = None, hand: Union[Hand, str] = DEFAULT_HAND,
                 models: Optional[GraspModels] = None):
        self.model = obj if isinstance(obj, TouchModel) else TouchModel(obj, hand)
        self.settings = settings or TouchSettings()
        self.settings.options()  # names checked now
        est = np.asarray(estimate, dtype=float).ravel()
        if est.shape == (3,):
            est = np.append(est, 1.0)
        if est.shape != (4,) or not np.all(np.isfinite(est)):
            raise ValueError(f"estimate: expected finite (x, y, yaw) or (x, y, yaw, scale), got {estimate}")
        if models is not None and models.family != "top":
            raise ValueError(f"models: the touch planner plans top grasps; got the {models.family} family's models")
        self.models = models
        self.initial = est.copy()
        self.estimate = est.copy()
        self.results: list = []

    @property
    def belief(self) -> np.ndarray:
        """The point estimate (x, y, yaw, scale)."""
        return self.estimate

    @property
    def spread(self) -> float:
        s = self.settings.spread
        return float(self.model.hand.core.spread_default if s is None else s)

    def plan(self) -> TouchPlan:
        """The touch at the estimate (no grasp models), or the models' most stable relative grasp
        (the highest P(S) node of their table) placed at the estimated pose, at the models' spread."""
        x, y, yaw, _ = self.estimate
        if self.models is None:
            return TouchPlan(top_grasp(x, y, yaw, self.spread), np.array([x, y, yaw]), "touch", self.estimate.copy())
        best = self.models.table().best_relative_grasps(1)[0]
        a = absolute_planar_pose(best[None, :], self.estimate[None, :3])[0]
        return TouchPlan(top_grasp(*a, self.models.spread), a, "stability", self.estimate.copy())

    def observe(self, grasp: Union[TouchPlan, TouchGrasp], measurement: TouchReadings) -> EstimateResult:
        """Fits the model to the measurement (the hand's TouchReadings) of the executed grasp (a
        TouchPlan or a TouchGrasp); the estimate is kept when the grasp missed the object."""
        readings = measurement
        touch = grasp.touch if isinstance(grasp, TouchPlan) else grasp
        if not isinstance(touch, TouchGrasp):
            raise TypeError(f"grasp: expected the executed TouchPlan or TouchGrasp, got {type(grasp).__name__}")
        if not isinstance(readings, TouchReadings):
            raise TypeError(f"measurement: expected the hand's TouchReadings, got {type(readings).__name__}")
        r = self.model.estimate(touch, readings, self.estimate, self.settings.options())
        if r.status == EstimateStatus.estimated:
            self.estimate = np.asarray(r.state, dtype=float).copy()
        self.results.append(r)
        return r
