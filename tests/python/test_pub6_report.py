"""pub6's report writes its tables as CSV and a plot, as the other experiments do: counts from four
hand-made trials whose transitions are known."""
import csv

from bayesgrasp.experiments.registry import get_experiment
from bayesgrasp.experiments.tactile_fusion import transitions, write_report


def trial(lifts, eps, vision_lifted):
    return {"registrations": [{"model": "mug/1", "weight": 0.6}, {"model": "mug/2", "weight": 0.4}],
            "rounds": [{"round": k, "lifted": l, "epsilon": e, "weights": [0.6 - 0.1 * k, 0.4 + 0.1 * k]}
                       for k, (l, e) in enumerate(zip(lifts, eps))],
            "vision_only": {"lifted": vision_lifted}}


def test_pub6_writes_csv_tables_and_a_plot(tmp_path):
    results = {"all": [("a", trial([False, True, True, True], [0.0, 0.1, 0.1, 0.1], False)),
                       ("b", trial([True, False, False, False], [0.1, 0.0, 0.0, 0.0], True)),
                       ("c", trial([False, False, False, True], [0.0, 0.0, 0.0, 0.2], False)),
                       ("d", trial([False, False, False, False], [0.0, 0.0, 0.0, 0.0], False))]}
    t = transitions(results["all"])
    assert (t.unstable_to_stable, t.stable_to_unstable, t.cumulative_success_by_round) == (1, 1, [1, 2, 2, 3])
    write_report(get_experiment("pub6"), results, tmp_path)
    rows = {r["measure"]: r for r in csv.DictReader(open(tmp_path / "transitions.csv"))}
    assert rows["unstable_to_stable"]["ours"] == "1" and rows["success_after_round_3"]["thesis"] == "78"
    rounds = list(csv.DictReader(open(tmp_path / "rounds.csv")))
    assert len(rounds) == 16 and rounds[-1]["top_model"] == "mug/2"          # weights 0.3 / 0.7 in round 3
    assert len(list(csv.DictReader(open(tmp_path / "targets.csv")))) == 5
    assert (tmp_path / "cumulative_success.png").stat().st_size > 5000
    assert "cumulative_success.png" in (tmp_path / "summary.md").read_text()
    assert "issue" not in (tmp_path / "summary.md").read_text()           # a product's report names no tracker


def test_pub5_scales_writes_its_grid_as_a_picture(tmp_path):
    """pub5_scales' report draws each density's success over the s_t x s_R grid (as every
    experiment writes a PNG); the numbers in its cells are the grid table's."""
    import numpy as np
    from PIL import Image

    from bayesgrasp.experiments.category_scales import DENSITIES, GRID, write_report as scales_report

    def run(obj, wins):
        return {"object": obj, "tasks": {"top": {m: {"success": m in wins} for m in DENSITIES}}}

    results = {name: [(f"{name}-{i}", run(f"mug/{i}", {"laplace"} if k % 2 else {"baseline", "gaussian"}))
                      for i in range(2)] for k, name in enumerate(GRID)}
    written = scales_report(get_experiment("pub5_scales"), results, tmp_path)
    png = tmp_path / "scales.png"
    assert png.stat().st_size > 5000 and "scales.png" in (tmp_path / "summary.md").read_text()
    assert np.asarray(Image.open(png)).std() > 10                           # drawn, not blank
    assert written.out == tmp_path and {r["laplace"] for r in written.summary["grid"]} == {0.0, 1.0}
