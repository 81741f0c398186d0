"""Property-based fuzzing of the bindings (Hypothesis; issue 18).

Arrays of any shape, dtype and memory order, empty ones, NaN, infinity, huge values and integer
extremes go into the public calls. The property: a result or a ValueError/TypeError, never a crash,
never NaN or infinity in a result without a warning. Each target runs in a child interpreter, so a
segfault fails its test (with the last input, written before every call) instead of ending pytest.

Refusing is not enough to pass: every example calls the target twice, with an arbitrary input and
with one from a well-formed strategy (valid shapes and values, any memory order). Each well-formed
case must return a result, and so must at least ``MIN_ACCEPTED_SHARE`` of all cases, so a binding
that refuses every input fails.

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
# Share of the cases (calls) that must return a result. Each example calls the binding once with a
# well-formed input and once with an arbitrary one (see _child), and every well-formed case must
# return a result, so a correct binding scores at least 50%, by construction rather than by the
# luck of the draw: derandomize=True fixes which inputs are drawn (for given strategies, test code
# and Hypothesis version), but not how many of each kind a per-case coin gives (over hundreds of
# seeded runs at 25 examples a 1:1 coin gave as few as 1 well-formed case, a 3:1 coin as few as 0
# arbitrary ones). 40% stays below that floor whatever Hypothesis draws, and a binding that
# refuses every input scores 0%.
MIN_ACCEPTED_SHARE = 0.4
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
        return _layout(draw, a)

    def _layout(draw, a):
        layout = draw(st.sampled_from(["C", "F", "strided"]))
        if layout == "F" and a.ndim >= 2:
            a = np.asfortranarray(a)
        elif layout == "strided" and a.ndim >= 1 and a.shape[0] > 0:
            a = np.repeat(a, 2, axis=0)[::2]
        return a

    @st.composite
    def any_order(draw, a):
        """The array ``a`` in C order, Fortran order or as a strided view."""
        return _layout(draw, a)

    @st.composite
    def good(draw, shape, lo=-1.0, hi=1.0):
        """A well-formed array: float64, the given shape, finite values in [lo, hi], any memory order."""
        a = draw(hnp.arrays(np.float64, shape, elements=st.floats(lo, hi, allow_subnormal=False)))
        return _layout(draw, a)

    ints = st.sampled_from(INT_EXTREMES)
    small_ints = st.one_of(st.integers(-2, 8), st.sampled_from(INT_EXTREMES))
    floats = st.one_of(st.floats(-2.0, 2.0), st.sampled_from(FLOAT_SPECIALS))
    return st, arrays, good, any_order, ints, small_ints, floats


# ---- the targets: name -> (arbitrary inputs, well-formed inputs, call, finite) ---------------------
# Each example draws one input of each kind (see _child): the arbitrary one probes the checks, the
# well-formed one (valid shapes, dtypes and values in any memory order) makes sure that a binding
# which refuses everything cannot pass. Well-formed dicts carry "_well_formed": True.
def _targets():
    st, arrays, good, any_order, ints, small_ints, floats = _strategies()
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

    # ---- well-formed inputs: sizes first, then arrays of those sizes ----
    rows = st.integers(1, 6)
    seeds = st.one_of(st.integers(0, 1000), st.sampled_from([0, 2**32 + 3, 2**63 - 1, 2**64 - 1]))
    threads = st.integers(0, 3)   # 0 = all cores

    @st.composite
    def ok_gp_fit(draw):
        n = draw(rows)
        return dict(exact=draw(st.booleans()), iters=draw(st.integers(0, 5)), threads=draw(threads),
                    X=draw(good((n, 2))), y=draw(good((n,))), Xq=draw(good((draw(rows), 2))))

    @st.composite
    def ok_belief(draw):
        d, n = draw(st.integers(1, 3)), draw(st.integers(1, 10))
        low = draw(good((d,)))
        return dict(low=low, high=low + draw(good((d,), 0.01, 2.0)), n=n, seed=draw(seeds),
                    ll=draw(good((n,), -20.0, 0.0)), m=draw(st.integers(0, 10)))

    @st.composite
    def ok_entropy(draw):
        n, k = draw(rows), draw(st.integers(1, 3))
        shape = (n, k) if draw(st.booleans()) else (draw(st.integers(1, 3)), n, k)   # one action or many
        return dict(lw=draw(good((n,), -5.0, 0.0)), mean=draw(good(shape)), var=draw(good(shape, 1e-4, 1.0)),
                    n=draw(st.integers(1, 20)), seed=draw(seeds), threads=draw(threads))

    @st.composite
    def ok_grid(draw):
        p, c0 = draw(rows), draw(st.integers(0, 1))          # the grid has two channels
        return dict(A=draw(good((draw(rows), 3), -0.15, 0.15)), P=draw(good((p, 3), -0.15, 0.15)),
                    lw=draw(good((p,), -5.0, 0.0)), c0=c0, nc=draw(st.integers(1, 2 - c0)), threads=draw(threads))

    @st.composite
    def contacts(draw, k, radius=0.03):
        """k contacts on a sphere about the origin: points and their outward unit normals."""
        az, el = draw(good((k,), 0.0, 2 * np.pi)), draw(good((k,), -1.5, 1.5))
        n = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
        return draw(any_order(radius * n)), draw(any_order(n))

    @st.composite
    def ok_epsilon(draw):
        P, N = draw(contacts(draw(st.integers(0, 5))))
        return dict(P=P, N=N, com=draw(good((3,), -0.01, 0.01)), scale=draw(st.floats(0.01, 0.2)),
                    mu=draw(st.floats(0.0, 1.5)), edges=draw(st.integers(3, 16)))

    @st.composite
    def ok_epsilon_batch(draw):
        counts = np.array(draw(st.lists(st.integers(0, 4), min_size=1, max_size=4)), dtype=np.int64)
        P, N = draw(contacts(int(counts.sum())))
        return dict(P=P, N=N, counts=counts, com=draw(good((3,), -0.01, 0.01)), threads=draw(threads))

    @st.composite
    def rotations(draw):
        q = draw(good((4,)))
        if np.linalg.norm(q) < 1e-3:
            q = np.array([1.0, 0.0, 0.0, 0.0])
        w, x, y, z = q / np.linalg.norm(q)
        return draw(any_order(np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                                        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                                        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])))

    @st.composite
    def ok_bounds(draw):
        d = draw(st.integers(1, 3))
        low = draw(good((d,)))
        return draw(any_order(np.stack([low, low + draw(good((d,), 0.01, 2.0))])))   # (2, D): low, high rows

    @st.composite
    def ok_cloud(draw):
        """A table (a jittered 6 x 6 grid of points on z = 0) and 0-10 points above it."""
        g = np.stack(np.meshgrid(np.linspace(-0.2, 0.2, 6), np.linspace(-0.2, 0.2, 6)), -1).reshape(-1, 2)
        table = np.c_[g + draw(good(g.shape, -0.01, 0.01)), draw(good((len(g),), -0.002, 0.002))]
        above = draw(good((draw(st.integers(0, 10)), 3), 0.0, 0.1))
        return draw(any_order(np.concatenate([table, above])))

    def both(arbitrary, well_formed):
        return arbitrary, well_formed.map(lambda d: {**d, "_well_formed": True})

    return {
        "gp_fit_predict": (*both(st.fixed_dictionaries(dict(
            exact=st.booleans(), iters=st.integers(0, 5), threads=small_ints, X=arrays(cols=2), y=arrays(ndim=1),
            Xq=arrays(cols=2))), ok_gp_fit()), gp_fit_predict, True),
        "core_gp_sample": (*both(st.fixed_dictionaries(dict(
            exact=st.booleans(), Xq=arrays(cols=2), n=small_ints, seed=ints, noise=st.booleans(),
            joint=st.booleans())), st.fixed_dictionaries(dict(
            exact=st.booleans(), Xq=rows.flatmap(lambda m: good((m, 2))), n=st.integers(1, 4), seed=seeds,
            noise=st.booleans(), joint=st.booleans()))), core_gp_sample, True),
        "core_gp_predict": (*both(
            st.fixed_dictionaries(dict(exact=st.booleans(), Xq=arrays(cols=2), noise=st.booleans())),
            st.fixed_dictionaries(dict(exact=st.booleans(), Xq=rows.flatmap(lambda m: good((m, 2))),
                                       noise=st.booleans()))), core_gp_predict, True),
        "particle_belief": (*both(st.fixed_dictionaries(dict(
            low=arrays(ndim=1), high=arrays(ndim=1), n=small_ints, seed=ints, ll=arrays(ndim=1, max_rows=10),
            m=small_ints)), ok_belief()), particle_belief, False),
        "posterior_entropy": (*both(st.fixed_dictionaries(dict(
            lw=arrays(ndim=1), mean=arrays(), var=arrays(), n=small_ints, seed=ints, threads=small_ints)),
            ok_entropy()), posterior_entropy, False),
        "grid_pairs": (*both(st.fixed_dictionaries(dict(
            A=arrays(cols=3), P=arrays(cols=3), c0=small_ints, nc=small_ints, threads=small_ints)), ok_grid()),
            grid_pairs, True),
        "grid_entropy": (*both(st.fixed_dictionaries(dict(
            A=arrays(cols=3), P=arrays(cols=3), lw=arrays(ndim=1), c0=small_ints, nc=small_ints,
            threads=small_ints)), ok_grid()), grid_entropy, False),
        "epsilon_volume": (*both(st.fixed_dictionaries(dict(
            P=arrays(cols=3), N=arrays(cols=3), com=arrays(ndim=1), scale=floats, mu=floats,
            edges=small_ints)), ok_epsilon()), epsilon_volume, True),
        "epsilon_volume_batch": (*both(st.fixed_dictionaries(dict(
            P=arrays(cols=3), N=arrays(cols=3), counts=arrays(ndim=1), com=arrays(ndim=1), threads=small_ints)),
            ok_epsilon_batch()), epsilon_volume_batch, True),
        "rotation_error": (*both(st.fixed_dictionaries(dict(Ra=arrays(cols=3), Rb=arrays(cols=3))),
                                 st.fixed_dictionaries(dict(Ra=rotations(), Rb=rotations()))), rotation_error, True),
        "pso": (*both(st.fixed_dictionaries(dict(bounds=arrays(cols=2), n=small_ints, seed=ints)),
                      st.fixed_dictionaries(dict(bounds=ok_bounds(), n=st.integers(1, 8), seed=seeds))), pso, True),
        "world_grasps": (*both(st.fixed_dictionaries(dict(xyyaw=arrays(cols=3, max_rows=3), threads=small_ints)),
                               st.fixed_dictionaries(dict(xyyaw=st.integers(1, 3).flatmap(
                                   lambda k: good((k, 3), -0.1, 0.1)), threads=threads))), world_grasps, True),
        "segment_table": (*both(st.fixed_dictionaries(dict(cloud=arrays(cols=3, max_rows=40))),
                                st.fixed_dictionaries(dict(cloud=ok_cloud()))), segment, False),
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
    from hypothesis import strategies as st

    arbitrary, well_formed, call, finite = _targets()[name]
    counts = {"target": name, "examples": 0, "cases": 0, "results": 0, "value_errors": 0, "type_errors": 0,
              "warned": 0, "well_formed": 0, "well_formed_results": 0}

    def one(a):
        counts["cases"] += 1
        counts["well_formed"] += bool(a.get("_well_formed"))
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
        counts["well_formed_results"] += bool(a.get("_well_formed"))
        if caught:
            counts["warned"] += 1
            return
        if finite:
            for f in _floats_in(result):
                assert np.all(np.isfinite(f)), f"{name}: NaN or infinity in a result without a warning: {result!r}"

    # Every example is a pair, one case of each kind: the split is exactly half and half whatever
    # Hypothesis draws (a coin or st.one_of per case splits 25 derandomized examples unevenly, which
    # leaves either the share or the arbitrary inputs to chance).
    @settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.tuples(well_formed, arbitrary))
    def case(pair):
        counts["examples"] += 1
        for a in pair:
            one(a)

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
    assert counts["examples"] >= min(EXAMPLES, 10)
    assert counts["well_formed"] == counts["examples"] == counts["cases"] - counts["well_formed"], counts
    # A binding that refuses everything must not pass: a share of the cases has to return a result,
    # and every well-formed case must.
    assert counts["results"] >= MIN_ACCEPTED_SHARE * counts["cases"], (
        f"{name}: only {counts['results']} of {counts['cases']} cases returned a result "
        f"({counts['well_formed_results']} of {counts['well_formed']} well-formed ones); counts: {counts}")
    assert counts["well_formed_results"] == counts["well_formed"], (
        f"{name}: {counts['well_formed'] - counts['well_formed_results']} well-formed cases were refused; "
        f"counts: {counts}")


if __name__ == "__main__":
    _child(sys.argv[1], Path(sys.argv[2]), sys.argv[3] if len(sys.argv) > 3 else "")
