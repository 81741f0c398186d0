"""The experiments by name. Each module of experiments registers its own (see
:mod:`.pose_uncertainty`; the package imports every such module); the driver (:mod:`.driver`)
runs any of them the same way, in three steps: prepare (what the runs share), run one (a
(method, object, run index) -> a typed record (:mod:`.run_records`) whose ``to_dict()`` is stored), report (tables, prose and figures from
the stored runs; each experiment's statistics, prose and figures are modules of their own)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional, Sequence

if TYPE_CHECKING:
    from ..loop.context import RunContext
    from .report import Report

#: The run context's settings an experiment's runs may read, besides the hand, the cache and the
#: seed that every one reads (``--set episode.FIELD`` is measurement_noise).
CONTEXT_SETTINGS = ("success", "lift", "families", "models", "planner", "measurement_noise")

#: (experiment, object, run index, seed) -> a record with ``to_dict()`` (or a JSON-ready dict);
#: module level (sent to workers).
RunFunction = Callable[[str, str, int, int], Any]


@dataclass(frozen=True)
class Experiment:
    """name, objects and runs per object by default, the methods compared (one stored series per
    method), a one-line description, and three functions:

    * ``make_run(experiment, method, ctx)`` -> (series key in the result store, RunFunction);
    * ``report(experiment, results, out)`` -> :class:`~.report.Report`; ``results`` maps method ->
      [(RunKey, dict)]; writes summary.md, summary.json, tables and plots into ``out``;
    * ``prepare_object(experiment, object, ctx)`` (optional): what the runs of one object share
      (its models), built before the runs as an engine task per object (in parallel), into the
      disk cache the runs then read;
    * ``prepare(experiment, objects, ctx)`` (optional): what the runs share, built once in the
      driver's process before them (task grasps: their disk cache is then shared by the workers);
    * ``finish(experiment, objects, ctx, out)`` (optional): extra figures after the report;

    ``reads``: which of :data:`CONTEXT_SETTINGS` its runs read (the command line refuses the
    others, so that no option is silently dropped); and ``seed_name``: the name its run seeds
    derive from (:func:`.runner.run_seed`; default its own): experiments that share one see the
    same problems (pub1_variants pub1's, the pub6 variants pub6's). A run is given its seed and
    uses it, so the seed stored with a result is the one it was made with.
    """

    name: str
    objects: Sequence[str]
    runs: int
    description: str
    make_run: Callable[["Experiment", str, "RunContext"], tuple]
    report: Callable[["Experiment", Dict[str, list], Path], "Report"]
    methods: Sequence[str] = ("stability",)
    finish: Optional[Callable[["Experiment", List[str], "RunContext", Path], None]] = None
    prepare: Optional[Callable[["Experiment", List[str], "RunContext"], None]] = None
    prepare_object: Optional[Callable[["Experiment", str, "RunContext"], None]] = None
    reads: Sequence[str] = CONTEXT_SETTINGS
    seed_name: Optional[str] = None

    def __post_init__(self):
        unknown = set(self.reads) - set(CONTEXT_SETTINGS)
        if unknown:
            raise ValueError(f"reads: {sorted(unknown)} are not run-context settings ({', '.join(CONTEXT_SETTINGS)})")

    @property
    def seeds(self) -> str:
        """The name the run seeds derive from."""
        return self.seed_name or self.name


EXPERIMENTS: Dict[str, Experiment] = {}


def register(experiment: Experiment) -> Experiment:
    if experiment.name in EXPERIMENTS:
        raise ValueError(f"experiment {experiment.name!r} is registered twice")
    EXPERIMENTS[experiment.name] = experiment
    return experiment


def get_experiment(name: str) -> Experiment:
    if name not in EXPERIMENTS:
        raise ValueError(f"unknown experiment {name!r}; one of: {', '.join(EXPERIMENTS)}")
    return EXPERIMENTS[name]


def experiment_names() -> List[str]:
    return list(EXPERIMENTS)
