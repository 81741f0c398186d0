"""average_rows: the mean over the objects, per attempt, of the figures an object has (NaN where
no run of that object made the attempt); NaN without a warning when no object has it."""
import math
import warnings

from bayesgrasp.experiments.pose_uncertainty_stats import average_rows


def _row(obj, attempt, epsilon, runs=2, made=2):
    return {"object": obj, "attempt": attempt, "runs": runs, "made": made, "epsilon": epsilon}


def test_the_mean_skips_objects_without_the_figure_and_is_nan_when_none_has_it():
    rows = [_row("cube", 1, 0.2), _row("mug", 1, 0.4), _row("cube", 2, float("nan"), made=0), _row("mug", 2, 0.1, made=1)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        one, two, three = average_rows(rows + [_row("cube", 3, float("nan"), made=0), _row("mug", 3, float("nan"), made=0)],
                                       attempts=3)
    assert math.isclose(one["epsilon"], 0.3) and (one["runs"], one["made"]) == (4, 4)
    assert math.isclose(two["epsilon"], 0.1) and two["made"] == 1
    assert math.isnan(three["epsilon"]) and three["made"] == 0
