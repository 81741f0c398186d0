"""Property-based fuzzing of the bindings (Hypothesis; issue 18).

Arrays of any shape, dtype and memory order, empty ones, NaN, infinity, huge values and integer
extremes go into the public calls. The property: a result or a ValueError/TypeError, never a crash,
never NaN or infinity in a result without a warning. Each target runs in a child interpreter, so a
segfault fails its test (with the last input, written before every call) instead of ending pytest.

``BAYESGRASP_FUZZ_EXAMPLES`` sets the examples per target (25 here; ``make fuzz`` runs 1000), and
``BAYESGRASP_FUZZ_REPORT`` names a JSON file to which each child adds its counts.
"""
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = int(os.environ.get("BAYESGRASP_FUZZ_EXAMPLES", "25"))
CHILD_TIMEOUT = float(os.environ.get("BAYESGRASP_FUZZ_TIMEOUT", str(max(120.0, 2.0 * EXAMPLES))))

INT_EXTREMES = [0, 1, 2, 3, -1, 7, 2**31 - 1, -(2**31), 2**31, 2**32 + 3, 2**63 - 1, 2**64, 2**70]
FLOAT_SPECIALS = [0.0, -0.0, 1e-300, 1e300, -1e300, np.nan, np.inf, -np.inf, 1e155]


# ---- strategies (imported lazily: only the child needs Hypothesis) -------------------------------
def _strategies():
    from hypothesis import strategies as st
    from hypothesis.extra import numpy as hnp

    # float64 most often, so that calls get past the dtype check and reach the core
    dtypes = st.sampled_from([np.float64] * 6 + [np.float32, np.int32, np.int64, np.bool_, np.complex128, object])

    @st.composite
    def arrays(draw, cols=None, ndim=None, max_rows=6):
        """Mostly the right column count (so calls get past the shape check), any dtype, memory order."""
        dt = draw(dtypes)
        nd = ndim if ndim is not None else draw(st.sampled_from([2, 2, 2, 1, 0, 3]))
        shape = []
        for d in range(nd):
            if d == nd - 1 and cols is not None and draw(st.integers(0, 5)) > 0:
                shape.append(cols)
            else:
                shape.append(draw(st.integers(0, max_rows)))
        shape = tuple(shape)
        if dt is object:
            return np.full(shape, "x", dtype=object)
        if np.issubdtype(dt, np.floating) or dt is np.complex128:
            el = st.one_of(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.sampled_from(FLOAT_SPECIALS))
            a = draw(hnp.arrays(np.float64, shape, elements=el)).astype(dt)
        elif dt is np.bool_:
            a = draw(hnp.arrays(np.bool_, shape))
        else:
            info = np.iinfo(dt)
            a = draw(hnp.arrays(dt, shape, elements=st.one_of(st.integers(-3, 3), st.sampled_from([info.min, info.max]))))
        layout = draw(st.sampled_from(["C", "F", "strided"]))
        if layout == "F" and a.ndim >= 2:
            a = np.asfortranarray(a)
        elif layout == "strided" and a.ndim >= 1 and a.shape[0] > 0:
            a = np.repeat(a, 2, axis=0)[::2]
        return a

    ints = st.sampled_from(INT_EXTREMES)
    small_ints = st.one_of(st.integers(-2, 8), st.sampled_from(INT_EXTREMES))
    floats = st.one_of(st.floats(-2.0, 2.0), st.sampled_from(FLOAT_SPECIALS))
    return st, arrays, ints, small_ints, floats


# ---- the targets: name -> (strategy builder, call) -----------------------------------------------
def _targets():
    st, arrays, ints, small_ints, floats = _strategies()
    from bayesgrasp import _core, belief, optim, quality, vision
    from bayesgrasp.gp import ExactGP, SparseGP

    rng = np.random.default_rng(0)
    Xt = rng.uniform(size=(12, 2))
    yt = np.sin(3 * Xt[:, 0])
    fitted = {"exact": _core.gp.ExactGP(), "sparse": _core.gp.SparseGP()}
    for m in fitted.values():
        m.fit(Xt, yt)
    grid = _core.belief.RelativePoseGrid([-0.1, -0.1], [0.1, 0.1], 3, 3, 4, np.zeros((36, 2)), np.full(2, np.nan))
    world = {}

    def the_world():
        if not world:
            from bayesgrasp.world import World

            world["w"] = World.single("cube")
        return world["w"]

    def gp_fit_predict(a):
        cls = ExactGP if a["exact"] else SparseGP
        m = cls(max_iter=int(a["iters"]), threads=a["threads"]).fit(a["X"], a["y"])
        return m.predict(a["Xq"], return_std=True)

    def core_gp_sample(a):
        m = fitted["exact" if a["exact"] else "sparse"]
        return m.sample(a["Xq"], a["n"], a["seed"], a["noise"], a["joint"])

    def core_gp_predict(a):
        m = fitted["exact" if a["exact"] else "sparse"]
        return m.predict(a["Xq"], a["noise"])

    def particle_belief(a):
        b = belief.ParticleBelief.uniform(a["low"], a["high"], a["n"], seed=a["seed"])
        b.reweight(a["ll"])
        b.resample(n=a["m"])
        return b.mean()

    def posterior_entropy(a):
        return belief.expected_posterior_entropy(a["lw"], a["mean"], a["var"], n_samples=a["n"], seed=a["seed"],
                                                 n_threads=a["threads"])

    def grid_pairs(a):
        return grid.interpolate_pairs(a["A"], a["P"], a["c0"], a["nc"], a["threads"])

    def grid_entropy(a):
        return grid.expected_posterior_entropy(a["A"], a["P"], a["lw"], a["c0"], 0, a["nc"], 5, 0, a["threads"])

    def epsilon_volume(a):
        return quality.epsilon_volume(a["P"], a["N"], a["com"], a["scale"], mu=a["mu"], n_edges=a["edges"])

    def epsilon_volume_batch(a):
        return _core.quality.epsilon_volume_batch(a["P"], a["N"], a["counts"], a["com"], 0.05, 0.5, 8, True,
                                                  a["threads"])

    def rotation_error(a):
        return vision.rotation_error(a["Ra"], a["Rb"])

    def pso(a):
        return optim.pso(lambda X: np.sum(np.asarray(X) ** 2, axis=1), a["bounds"], n_particles=a["n"],
                         max_iter=3, seed=a["seed"]).fun

    def world_grasps(a):
        b = the_world().grasp_batch(a["xyyaw"], threads=a["threads"])
        return b.epsilon

    def segment(a):
        r = vision.segment_table(a["cloud"])
        return r.plane

    return {
        "gp_fit_predict": (st.fixed_dictionaries(dict(
            exact=st.booleans(), iters=st.integers(0, 5), threads=small_ints, X=arrays(cols=2), y=arrays(ndim=1),
            Xq=arrays(cols=2))), gp_fit_predict, True),
        "core_gp_sample": (st.fixed_dictionaries(dict(
            exact=st.booleans(), Xq=arrays(cols=2), n=small_ints, seed=ints, noise=st.booleans(),
            joint=st.booleans())), core_gp_sample, True),
        "core_gp_predict": (st.fixed_dictionaries(dict(exact=st.booleans(), Xq=arrays(cols=2), noise=st.booleans())),
                            core_gp_predict, True),
        "particle_belief": (st.fixed_dictionaries(dict(
            low=arrays(ndim=1), high=arrays(ndim=1), n=small_ints, seed=ints, ll=arrays(ndim=1, max_rows=10),
            m=small_ints)), particle_belief, False),
        "posterior_entropy": (st.fixed_dictionaries(dict(
            lw=arrays(ndim=1), mean=arrays(), var=arrays(), n=small_ints, seed=ints, threads=small_ints)),
            posterior_entropy, False),
        "grid_pairs": (st.fixed_dictionaries(dict(
            A=arrays(cols=3), P=arrays(cols=3), c0=small_ints, nc=small_ints, threads=small_ints)), grid_pairs, True),
        "grid_entropy": (st.fixed_dictionaries(dict(
            A=arrays(cols=3), P=arrays(cols=3), lw=arrays(ndim=1), c0=small_ints, nc=small_ints,
            threads=small_ints)), grid_entropy, False),
        "epsilon_volume": (st.fixed_dictionaries(dict(
            P=arrays(cols=3), N=arrays(cols=3), com=arrays(ndim=1), scale=floats, mu=floats,
            edges=small_ints)), epsilon_volume, True),
        "epsilon_volume_batch": (st.fixed_dictionaries(dict(
            P=arrays(cols=3), N=arrays(cols=3), counts=arrays(ndim=1), com=arrays(ndim=1), threads=small_ints)),
            epsilon_volume_batch, True),
        "rotation_error": (st.fixed_dictionaries(dict(Ra=arrays(cols=3), Rb=arrays(cols=3))), rotation_error, True),
        "pso": (st.fixed_dictionaries(dict(bounds=arrays(cols=2), n=small_ints, seed=ints)), pso, True),
        "world_grasps": (st.fixed_dictionaries(dict(xyyaw=arrays(cols=3, max_rows=3), threads=small_ints)),
                         world_grasps, True),
        "segment_table": (st.fixed_dictionaries(dict(cloud=arrays(cols=3, max_rows=40))), segment, False),
    }


TARGET_NAMES = ["gp_fit_predict", "core_gp_sample", "core_gp_predict", "particle_belief", "posterior_entropy",
                "grid_pairs", "grid_entropy", "epsilon_volume", "epsilon_volume_batch", "rotation_error", "pso",
                "world_grasps", "segment_table"]


def _floats_in(result):
    """Every float array or float inside a result (tuples, lists, arrays)."""
    if isinstance(result, (tuple, list)):
        for r in result:
            yield from _floats_in(r)
    elif isinstance(result, np.ndarray) and np.issubdtype(result.dtype, np.floating):
        yield result
    elif isinstance(result, float):
        yield np.asarray(result)


# ---- the child: one target, Hypothesis's loop, the last input on disk -----------------------------
def _child(name: str, last_input: Path, report: str) -> None:
    from hypothesis import HealthCheck, given, settings

    strategy, call, finite = _targets()[name]
    counts = {"target": name, "cases": 0, "results": 0, "value_errors": 0, "type_errors": 0, "warned": 0}

    @settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def case(a):
        counts["cases"] += 1
        last_input.write_text(repr(a))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = call(a)
            except ValueError:
                counts["value_errors"] += 1
                return
            except TypeError:
                counts["type_errors"] += 1
                return
        counts["results"] += 1
        if caught:
            counts["warned"] += 1
            return
        if finite:
            for f in _floats_in(result):
                assert np.all(np.isfinite(f)), f"{name}: NaN or infinity in a result without a warning: {result!r}"

    case()
    print(json.dumps(counts))
    if report:
        with open(report, "a") as f:
            f.write(json.dumps(counts) + "\n")


@pytest.mark.parametrize("name", TARGET_NAMES)
def test_a_binding_answers_any_input_with_a_result_or_a_clear_error(name, tmp_path):
    last = tmp_path / "last_input.txt"
    env = dict(os.environ, PYTHONFAULTHANDLER="1")
    r = subprocess.run([sys.executable, __file__, name, str(last), os.environ.get("BAYESGRASP_FUZZ_REPORT", "")],
                       capture_output=True, text=True, timeout=CHILD_TIMEOUT, env=env)
    where = f"last input: {last.read_text() if last.exists() else '(none)'}"
    assert r.returncode >= 0, f"{name} crashed with signal {-r.returncode}; {where}\n{r.stderr[-3000:]}"
    assert r.returncode == 0, f"{name}: {r.stderr[-3000:]}\n{where}"
    counts = json.loads(r.stdout.strip().splitlines()[-1])
    assert counts["cases"] >= min(EXAMPLES, 10)


if __name__ == "__main__":
    _child(sys.argv[1], Path(sys.argv[2]), sys.argv[3] if len(sys.argv) > 3 else "")
