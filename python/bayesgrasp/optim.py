"""Batch optimisers (minimisation) from the C++ core.

Global: :func:`pso` (particle swarm, constriction parameters), :func:`simulated_annealing`,
:func:`firefly`. Local: :func:`steepest_descent`, :func:`levenberg_marquardt` (least squares),
:func:`trust_region` (dogleg with BFGS; Pub. VI's pose update, Eq. 4.4).

Objectives are *vectorised*: ``f(X)`` takes an ``(N, D)`` array (one candidate per row) and returns
``(N,)`` values; the optimisers call it once per iteration with the whole swarm, finite-difference
stencil or batch. The C++ loop runs without the GIL and takes it only around the call. Pass a
built-in name (``"sphere"``, ``"rastrigin"``, ``"ackley"``, ``"rosenbrock"``) to use a C++ objective.
Non-finite values count as +infinity. Every function returns an :class:`OptimizeResult`.

Example::

    from bayesgrasp import optim
    res = optim.pso(lambda X: (X ** 2).sum(axis=1), bounds=([-1, -1], [1, 1]), seed=0)
    res.x, res.fun, res.nfev
"""
from __future__ import annotations

from typing import Callable, Optional, Sequence, Tuple, Union

from bayesgrasp._args import with_fields
import numpy as np

from bayesgrasp import _core

_c = _core.optim

Objective = Union[str, Callable[[np.ndarray], np.ndarray]]
Bounds = Union[Tuple[Sequence[float], Sequence[float]], np.ndarray]

__all__ = ["OptimizeResult", "PSOOptions", "AnnealingOptions", "FireflyOptions", "DescentOptions", "LMOptions",
           "TrustRegionOptions", "pso", "simulated_annealing", "firefly", "steepest_descent",
           "levenberg_marquardt", "trust_region", "rastrigin", "ackley", "sphere", "rosenbrock"]

#: What every optimiser returns (bound C++ class): x (D,) best point; fun (for
#: ``levenberg_marquardt``: 1/2 |r|^2); nit iterations; nfev rows passed to the objective; history
#: best value after each iteration (if ``record_history``); converged (a tolerance or the target was
#: met); message (why it stopped).
OptimizeResult = _c.OptimizeResult
PSOOptions = _c.PSOOptions
AnnealingOptions = _c.AnnealingOptions
FireflyOptions = _c.FireflyOptions
DescentOptions = _c.DescentOptions
LMOptions = _c.LMOptions
TrustRegionOptions = _c.TrustRegionOptions


def _bounds(bounds, name="bounds"):
    """(low, high) pair or a (2, D) / (D, 2) array -> two float arrays."""
    if bounds is None:
        return None, None
    if isinstance(bounds, (tuple, list)) and len(bounds) == 2:
        low, high = (np.asarray(b, dtype=float).ravel() for b in bounds)
    else:
        b = np.asarray(bounds, dtype=float)
        if b.ndim == 2 and b.shape[0] == 2:
            low, high = b[0], b[1]
        elif b.ndim == 2 and b.shape[1] == 2:
            low, high = b[:, 0], b[:, 1]
        else:
            raise ValueError(f"{name}: expected (low, high) or an array of shape (2, D), got {b.shape}")
    if low.shape != high.shape:
        raise ValueError(f"{name}: low has shape {low.shape}, high {high.shape}")
    return low, high


def _objective(fun: Objective, name="objective"):
    if isinstance(fun, str) or callable(fun):
        return fun
    raise ValueError(f"{name}: expected a vectorised callable (N, D) -> (N,) or a built-in name, got {type(fun)}")


def pso(fun: Objective, bounds: Bounds, options: Optional["PSOOptions"] = None, **fields) -> OptimizeResult:
    """Particle swarm optimisation (global best) of ``fun`` over the box ``bounds``.

    ``options``: a :class:`PSOOptions` (defaults: Clerc & Kennedy's constriction, inertia 0.7298,
    c1 = c2 = 1.49618); its fields may also be given by keyword (``n_particles=80, seed=3``).
    Velocities are clamped to ``vmax_fraction`` of the range; particles leaving the box are put on
    its face with that velocity component zeroed. Stops after ``max_iter`` swarm updates, when the
    best value reaches ``target``, or after ``stall_iter`` iterations improving by at most ``ftol``.
    nfev = n_particles * (nit + 1).
    """
    low, high = _bounds(bounds)
    return _c.pso(_objective(fun), low, high, with_fields(PSOOptions, options, fields))


def simulated_annealing(fun: Objective, bounds: Bounds, options: Optional["AnnealingOptions"] = None,
                        **fields) -> OptimizeResult:
    """Simulated annealing: ``n_chains`` Metropolis chains evaluated as one batch per iteration.

    ``options``: an :class:`AnnealingOptions`, its fields also by keyword. Gaussian random-walk
    proposals (std ``step`` x range, reflected into the box), each chain adapting its step every
    ``adapt_interval`` iterations towards ``target_acceptance``; geometric cooling
    T_k = t0 * cooling^k (t0 <= 0: the std of f over the initial points). nfev = n_chains * (nit + 1).
    """
    low, high = _bounds(bounds)
    return _c.simulated_annealing(_objective(fun), low, high, with_fields(AnnealingOptions, options, fields))


def firefly(fun: Objective, bounds: Bounds, options: Optional["FireflyOptions"] = None, **fields) -> OptimizeResult:
    """The firefly algorithm (Yang 2008). ``options``: a :class:`FireflyOptions`, its fields also by keyword.

    Firefly i moves towards each brighter j by beta0 exp(-gamma r_ij^2)(x_j - x_i) plus
    alpha (u - 1/2); alpha decays by ``alpha_decay`` per generation. Distances and steps are in
    unit-box coordinates (each dimension divided by its range). nfev = n_fireflies * (nit + 1).
    """
    low, high = _bounds(bounds)
    return _c.firefly(_objective(fun), low, high, with_fields(FireflyOptions, options, fields))


def steepest_descent(fun: Objective, x0, bounds: Optional[Bounds] = None, options: Optional["DescentOptions"] = None,
                     **fields) -> OptimizeResult:
    """Steepest descent from ``x0``: central-difference gradients (one batch of 2D rows, step
    h * max(1, |x_k|)) and Armijo backtracking; projected onto ``bounds`` if given.
    ``options``: a :class:`DescentOptions`, its fields also by keyword."""
    low, high = _bounds(bounds)
    return _c.steepest_descent(_objective(fun), np.asarray(x0, dtype=float), low, high,
                               with_fields(DescentOptions, options, fields))


def levenberg_marquardt(residuals: Callable[[np.ndarray], np.ndarray], x0, bounds: Optional[Bounds] = None,
                        options: Optional["LMOptions"] = None, **fields) -> OptimizeResult:
    """Levenberg-Marquardt on 1/2 |r(x)|^2. ``residuals`` maps (N, D) -> (N, R); the Jacobian is
    taken by central differences in one batch call. ``fun`` in the result is 1/2 |r|^2.
    ``options``: an :class:`LMOptions`, its fields also by keyword."""
    if not callable(residuals):
        raise ValueError("residuals: expected a vectorised callable (N, D) -> (N, R)")
    low, high = _bounds(bounds)
    return _c.levenberg_marquardt(residuals, np.asarray(x0, dtype=float), low, high,
                                  with_fields(LMOptions, options, fields))


def trust_region(fun: Objective, x0, bounds: Optional[Bounds] = None, options: Optional["TrustRegionOptions"] = None,
                 **fields) -> OptimizeResult:
    """Dogleg trust region with central-difference gradients and BFGS Hessian updates, for scalar
    objectives such as a negative log posterior of a pose (Eq. 4.4). ``options``: a
    :class:`TrustRegionOptions`, its fields also by keyword."""
    low, high = _bounds(bounds)
    return _c.trust_region(_objective(fun), np.asarray(x0, dtype=float), low, high,
                           with_fields(TrustRegionOptions, options, fields))


def _builtin(name):
    def f(X):
        return _c.evaluate_builtin(name, np.atleast_2d(np.asarray(X, dtype=float)))
    f.__name__ = name
    f.__doc__ = f"The {name} test function (C++), vectorised over the rows of X."
    return f


sphere = _builtin("sphere")
rastrigin = _builtin("rastrigin")
ackley = _builtin("ackley")
rosenbrock = _builtin("rosenbrock")
