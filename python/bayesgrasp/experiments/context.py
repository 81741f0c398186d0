"""What a command, an experiment or an episode needs from its caller, built once at the edge (the
CLI or the experiment driver) and passed down instead of threading each setting by hand."""
from __future__ import annotations

import sys
from dataclasses import dataclass, field, replace
from typing import Callable, Optional, Union

from ..models import GraspModels, ModelSettings, get_models
from ..models.settings import SUCCESS_CRITERIA
from ..objects import ObjectModel


def stderr_progress(message: str) -> None:
    """Progress messages go to stderr (stdout stays clean for --json)."""
    print(message, file=sys.stderr, flush=True)


@dataclass(frozen=True)
class RunContext:
    """hand: hand name or file; cache_dir: the model cache (None: $BAYESGRASP_CACHE/models);
    success: what a successful grasp is, "lift" (held in the physical lift test) or "epsilon"
    (epsilon above the models' eps_stable, the thesis's simulation criterion); lift: run the lift
    test (required by success "lift"; with "epsilon" it runs on stable grasps); threads: C++
    threads for batches (0 = all cores); seed: the base seed; progress: a callable taking a message
    (None: silent; not sent to worker processes); model_settings: how the grasp models are built
    (None: the defaults for the success criterion)."""

    hand: str = "barrett_bh8"
    cache_dir: Optional[str] = None
    success: str = "lift"
    lift: bool = True
    threads: int = 1
    seed: int = 0
    progress: Optional[Callable[[str], None]] = field(default=None, compare=False)
    model_settings: Optional[ModelSettings] = None   # None: ModelSettings(success=self.success)

    def __post_init__(self):
        if self.success not in SUCCESS_CRITERIA:
            raise ValueError(f"success: one of {', '.join(SUCCESS_CRITERIA)}; got {self.success!r}")
        if self.success == "lift" and not self.lift:
            raise ValueError("lift: success 'lift' needs the lift test (use success 'epsilon' to skip it)")
        if self.threads < 0:
            raise ValueError(f"threads: must be >= 0 (0 = all cores), got {self.threads}")
        if self.cache_dir is not None:
            object.__setattr__(self, "cache_dir", str(self.cache_dir))

    def say(self, message: str) -> None:
        if self.progress is not None:
            self.progress(message)

    def models(self, obj: Union[str, ObjectModel], settings: Optional[ModelSettings] = None) -> GraspModels:
        """The object's grasp models for this context's hand, cache and success criterion
        (memoised per process)."""
        settings = settings or self.model_settings or ModelSettings(success=self.success)
        return get_models(obj, self.hand, settings, cache_dir=self.cache_dir, progress=self.progress)

    def for_workers(self) -> "RunContext":
        """The same context without the progress callable (worker processes get it pickled)."""
        return replace(self, progress=None)
