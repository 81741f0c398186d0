"""Every setting that changes a run's result (:meth:`~bayesgrasp.loop.context.RunContext.result_settings`),
stored beside an experiment's results as JSON (``to_dict``); a resume under other values is refused
(:meth:`bayesgrasp.experiments.runner.ResultStore.check_settings`)."""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass

from ..models import ModelSettings
from ..planners import PlannerSettings


def plain(v):
    """A settings value as JSON would give it back (tuples as lists, numpy scalars as numbers)."""
    return json.loads(json.dumps(v, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))


@dataclass(frozen=True)
class ResultSettings:
    """bayesgrasp : str — the package version; cache_version : int — the model cache's
    hand : str — the hand's name; hand_file_sha256 : str — the first 16 hex digits of its file's digest
    success : str — the success criterion; lift : bool — the lift test on
    families : tuple — the grasp families planned from
    models : ModelSettings — the effective model settings; planner : PlannerSettings
    measurement_noise : float — std (rad) of the joint-angle noise
    run_seeds : str — how each run's seed is made
    """

    bayesgrasp: str
    cache_version: int
    hand: str
    hand_file_sha256: str
    success: str
    lift: bool
    families: tuple
    models: ModelSettings
    planner: PlannerSettings
    measurement_noise: float
    run_seeds: str

    def to_dict(self) -> dict:
        """As stored: plain JSON values, the model settings as in cache keys (``as_stored``)."""
        return {"bayesgrasp": self.bayesgrasp, "cache_version": self.cache_version, "hand": self.hand,
                "hand_file_sha256": self.hand_file_sha256, "success": self.success, "lift": self.lift,
                "families": list(self.families),
                "models": {k: plain(v) for k, v in self.models.as_stored().items()},
                "planner": {k: plain(v) for k, v in asdict(self.planner).items()},
                "measurement_noise": self.measurement_noise, "run_seeds": self.run_seeds}
