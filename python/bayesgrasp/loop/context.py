"""What a command, an experiment or an episode needs from its caller, built once at the edge (the
CLI or the experiment driver) and passed down instead of threading each setting by hand."""
from __future__ import annotations

import functools
import math
import sys
import time
from dataclasses import dataclass, field, replace
from typing import Callable, Optional, Sequence, Union

from .. import DEFAULT_HAND
from ..models import GraspModels, ModelSettings, get_models, parse_families
from ..models.settings import SUCCESS_CRITERIA
from ..objects import ObjectModel
from ..planners import PlannerSettings
from .result_settings import ResultSettings

#: How the run seeds are made, stored with the results: each run is given run_seed(--seed, the
#: experiment's seed name, object, run index) and uses it (stores without it derived seeds from
#: the series name and cannot be resumed: their stored seeds are not the ones the runs used).
RUN_SEEDS = "run_seed(seed, seed_name, object, run_index)"


@functools.lru_cache(maxsize=8)
def _loaded_hand(name: str):
    """The hand ``name`` loaded once per process (a context is sent to worker processes by its
    name; the loaded model is not picklable)."""
    from ..hand import Hand
    return Hand.load(name)


def stderr_progress(message: str) -> None:
    """Progress messages go to stderr (stdout stays clean for --json)."""
    print(message, file=sys.stderr, flush=True)


@dataclass(frozen=True)
class EpisodeOverrides:
    """The episode settings an experiment takes from its caller (``--set episode.FIELD=VALUE``)."""

    measurement_noise: float = 0.0


@dataclass(frozen=True)
class RunContext:
    """hand: hand name or file; cache_dir: the model cache (None: $BAYESGRASP_CACHE/models);
    success: what a successful grasp is, "lift" (held in the physical lift test) or "epsilon"
    (epsilon above the models' eps_stable, the thesis's simulation criterion); lift: run the lift
    test (required by success "lift"; with "epsilon" it runs on stable grasps); seed: the base seed
    (a command's --seed; the experiments derive each run's seed from it); progress: a callable taking a message
    (None: silent; not sent to worker processes); model_settings: how the grasp models are built
    (None: the defaults for the success criterion); families: the grasp families the planners
    choose from ("top", as in the thesis, and "side"; :mod:`bayesgrasp.models.families`);
    planner: the planners' settings (None: the defaults); measurement_noise: std (rad) of the
    Gaussian noise on the measured joint angles in the closed-loop experiments."""

    hand: str = DEFAULT_HAND
    cache_dir: Optional[str] = None
    success: str = "lift"
    lift: bool = True
    seed: int = 0
    progress: Optional[Callable[[str], None]] = field(default=None, compare=False)
    model_settings: Optional[ModelSettings] = None   # None: ModelSettings(success=self.success)
    families: tuple = ("top",)
    planner: Optional[PlannerSettings] = None
    measurement_noise: float = 0.0

    def __post_init__(self):
        if self.planner is not None and not isinstance(self.planner, PlannerSettings):
            raise ValueError(f"planner: a PlannerSettings or None, got {type(self.planner).__name__}")
        if not (isinstance(self.measurement_noise, (int, float)) and math.isfinite(self.measurement_noise)
                and self.measurement_noise >= 0):
            raise ValueError(f"measurement_noise: must be >= 0 (rad), got {self.measurement_noise!r}")
        try:
            object.__setattr__(self, "families", parse_families(self.families))
        except ValueError as e:
            raise ValueError(str(e)) from None
        if self.success not in SUCCESS_CRITERIA:
            raise ValueError(f"success: one of {', '.join(SUCCESS_CRITERIA)}; got {self.success!r}")
        if self.success == "lift" and not self.lift:
            raise ValueError("lift: off needs success 'epsilon' (--success epsilon): success 'lift' is decided by "
                             "the lift test")
        if self.cache_dir is not None:
            object.__setattr__(self, "cache_dir", str(self.cache_dir))

    @property
    def hand_model(self):
        """This context's hand, loaded (once per process): a :class:`~bayesgrasp.hand.Hand`."""
        return _loaded_hand(str(self.hand))

    def say(self, message: str) -> None:
        if self.progress is not None:
            self.progress(message)

    def models(self, obj: Union[str, ObjectModel], settings: Optional[ModelSettings] = None) -> GraspModels:
        """The object's grasp models for this context's hand, cache and success criterion
        (memoised per process)."""
        settings = settings or self.model_settings or ModelSettings(success=self.success)
        return get_models(obj, self.hand, settings, cache_dir=self.cache_dir, progress=self.progress)

    def models_of(self, objs: Sequence[Union[str, ObjectModel]], settings=None) -> list:
        """:meth:`models` of several objects, in order (``settings``: one ModelSettings for all, or
        one per object). Those not cached are announced first (how many, and that a first build
        takes minutes), and after each build the time left is estimated from the builds so far."""
        from ..models import models_cached

        default = self.model_settings or ModelSettings(success=self.success)
        each = list(settings) if isinstance(settings, (list, tuple)) else [settings] * len(objs)
        each = [s or default for s in each]
        todo = [not models_cached(o, self.hand, s, cache_dir=self.cache_dir) for o, s in zip(objs, each)]
        n = sum(todo)
        if n:
            self.say(f"models: {n} of {len(objs)} not cached; each is built once (minutes on 2 cores), "
                     f"later calls load them in seconds")
        out, built, spent = [], 0, 0.0
        for o, s, build in zip(objs, each, todo):
            t0 = time.perf_counter()
            out.append(self.models(o, s))
            if build:
                built, spent = built + 1, spent + time.perf_counter() - t0
                if built < n:
                    self.say(f"models: {built} of {n} built in {spent / 60:.1f} min; about "
                             f"{spent / built * (n - built) / 60:.0f} min left")
        return out

    def family_models(self, obj: Union[str, ObjectModel], settings: Optional[ModelSettings] = None) -> dict:
        """{family: GraspModels} for every family of this context (the same settings otherwise)."""
        settings = settings or self.model_settings or ModelSettings(success=self.success)
        if len(self.families) == 1:
            return {self.families[0]: self.models(obj, replace(settings, family=self.families[0]))}
        models = self.models_of([obj] * len(self.families), [replace(settings, family=f) for f in self.families])
        return dict(zip(self.families, models))

    def planner_settings(self) -> PlannerSettings:
        """The planners' settings of this context (the defaults when none were given)."""
        return self.planner or PlannerSettings()

    def result_settings(self) -> ResultSettings:
        """Every setting of this context that changes a run's result: the package and cache
        versions, the hand (its name and a digest of its file), the success criterion, the lift test
        on or off, the effective model and planner settings and how run seeds are made. Stored
        beside an experiment's results (``to_dict``); a resume with different values is refused
        (runner.ResultStore)."""
        import hashlib
        from pathlib import Path

        from .. import __version__
        from ..models.settings import CACHE_VERSION

        hand = self.hand_model
        text = Path(hand.path).read_bytes() if getattr(hand, "path", None) else hand.name.encode()
        return ResultSettings(__version__, CACHE_VERSION, hand.name, hashlib.sha256(text).hexdigest()[:16],
                              self.success, self.lift, tuple(self.families),
                              self.model_settings or ModelSettings(success=self.success), self.planner_settings(),
                              float(self.measurement_noise), RUN_SEEDS)

    def for_workers(self) -> "RunContext":
        """The same context without the progress callable (worker processes get it pickled)."""
        return replace(self, progress=None)


def context_from_plain(hand: str = DEFAULT_HAND, cache_dir: Optional[str] = None, seed: int = 0,
                       models: Optional[dict] = None, planner: Optional[dict] = None) -> RunContext:
    """A lift-judged :class:`RunContext` from plain values (a service's JSON body): ``models`` and
    ``planner`` are {field: value} overrides of ModelSettings and PlannerSettings (None or {}: the
    defaults). A wrong field or value is a ValueError naming ``models.FIELD`` or ``planner.FIELD``."""
    import dataclasses

    def build(cls, group: str, values: dict, **fixed):
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(values) - known)
        for name in fixed:
            if name in values:
                raise ValueError(f"{group}.{name}: fixed at {fixed[name]!r} here")
        if unknown:
            raise ValueError(f"{group}.{unknown[0]}: no such setting (known: {', '.join(sorted(known))})")
        for k, v in values.items():   # lists from JSON are the settings' tuples
            values[k] = tuple(v) if isinstance(v, list) else v
        try:
            return cls(**fixed, **values)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{group}.{e}") from None

    ms = build(ModelSettings, "models", dict(models), success="lift") if models else None
    ps = build(PlannerSettings, "planner", dict(planner)) if planner else None
    return RunContext(hand=hand, cache_dir=cache_dir, seed=int(seed), model_settings=ms, planner=ps)
