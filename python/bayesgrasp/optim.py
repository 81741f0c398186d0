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

from bayesgrasp._args import c_int, c_seed
import numpy as np

from bayesgrasp import _core

_c = _core.optim

Objective = Union[str, Callable[[np.ndarray], np.ndarray]]
Bounds = Union[Tuple[Sequence[float], Sequence[float]], np.ndarray]

__all__ = ["OptimizeResult", "pso", "simulated_annealing", "firefly", "steepest_descent",
           "levenberg_marquardt", "trust_region", "rastrigin", "ackley", "sphere", "rosenbrock"]

#: What every optimiser returns (bound C++ class): x (D,) best point; fun (for
#: ``levenberg_marquardt``: 1/2 |r|^2); nit iterations; nfev rows passed to the objective; history
#: best value after each iteration (if ``record_history``); converged (a tolerance or the target was
#: met); message (why it stopped).
OptimizeResult = _c.OptimizeResult


def _options(cls, settings: dict):
    """An options object of the bound class ``cls`` with the given fields (None keeps the default),
    each value converted to the type of the field's default."""
    o = cls()
    for name, value in settings.items():
        if value is None:
            continue
        default = getattr(o, name)
        if isinstance(default, bool):
            value = bool(value)
        elif isinstance(default, int):
            value = c_seed(value, name) if name == "seed" else c_int(value, name)
        elif isinstance(default, float):
            value = float(value)
        setattr(o, name, value)
    return o


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


def pso(fun: Objective, bounds: Bounds, *, n_particles: int = 40, max_iter: int = 200,
        inertia: float = 0.7298, c1: float = 1.49618, c2: float = 1.49618, vmax_fraction: float = 0.5,
        seed: int = 0, target: float = -np.inf, stall_iter: int = 0, ftol: float = 0.0,
        init: Optional[np.ndarray] = None, record_history: bool = False) -> OptimizeResult:
    """Particle swarm optimisation (global best) of ``fun`` over the box ``bounds``.

    Constriction-equivalent defaults (Clerc & Kennedy): inertia 0.7298, c1 = c2 = 1.49618.
    Velocities are clamped to ``vmax_fraction`` of the range; particles leaving the box are put on
    its face with that velocity component zeroed. Stops after ``max_iter`` swarm updates, when the
    best value reaches ``target``, or after ``stall_iter`` iterations improving by at most ``ftol``.
    nfev = n_particles * (nit + 1).
    """
    low, high = _bounds(bounds)
    o = _options(_c.PSOOptions, dict(n_particles=n_particles, max_iter=max_iter, inertia=inertia, c1=c1, c2=c2,
                                     vmax_fraction=vmax_fraction, seed=seed, target=target, stall_iter=stall_iter,
                                     ftol=ftol, init=init, record_history=record_history))
    return _c.pso(_objective(fun), low, high, o)


def simulated_annealing(fun: Objective, bounds: Bounds, *, n_chains: int = 16, max_iter: int = 1000,
                        t0: float = -1.0, cooling: float = 0.98, step: float = 0.1, step_min: float = 1e-9,
                        step_max: float = 0.5, adapt_interval: int = 10, target_acceptance: float = 0.2,
                        adapt_factor: float = 1.5, seed: int = 0, target: float = -np.inf,
                        init: Optional[np.ndarray] = None, record_history: bool = False) -> OptimizeResult:
    """Simulated annealing: ``n_chains`` Metropolis chains evaluated as one batch per iteration.

    Gaussian random-walk proposals (std ``step`` x range, reflected into the box), each chain
    adapting its step every ``adapt_interval`` iterations towards ``target_acceptance``; geometric
    cooling T_k = t0 * cooling^k (t0 <= 0: the std of f over the initial points).
    nfev = n_chains * (nit + 1).
    """
    low, high = _bounds(bounds)
    o = _options(_c.AnnealingOptions, dict(n_chains=n_chains, max_iter=max_iter, t0=t0, cooling=cooling, step=step,
                                           step_min=step_min, step_max=step_max, adapt_interval=adapt_interval,
                                           target_acceptance=target_acceptance, adapt_factor=adapt_factor,
                                           seed=seed, target=target, init=init, record_history=record_history))
    return _c.simulated_annealing(_objective(fun), low, high, o)


def firefly(fun: Objective, bounds: Bounds, *, n_fireflies: int = 25, max_iter: int = 100, beta0: float = 1.0,
            gamma: float = 1.0, alpha: float = 0.2, alpha_decay: float = 0.97, seed: int = 0,
            target: float = -np.inf, init: Optional[np.ndarray] = None,
            record_history: bool = False) -> OptimizeResult:
    """The firefly algorithm (Yang 2008).

    Firefly i moves towards each brighter j by beta0 exp(-gamma r_ij^2)(x_j - x_i) plus
    alpha (u - 1/2); alpha decays by ``alpha_decay`` per generation. Distances and steps are in
    unit-box coordinates (each dimension divided by its range). nfev = n_fireflies * (nit + 1).
    """
    low, high = _bounds(bounds)
    o = _options(_c.FireflyOptions, dict(n_fireflies=n_fireflies, max_iter=max_iter, beta0=beta0, gamma=gamma,
                                         alpha=alpha, alpha_decay=alpha_decay, seed=seed, target=target, init=init,
                                         record_history=record_history))
    return _c.firefly(_objective(fun), low, high, o)


def steepest_descent(fun: Objective, x0, bounds: Optional[Bounds] = None, *, max_iter: int = 500,
                     h: float = 1e-6, t0: float = 1.0, armijo: float = 1e-4, backtrack: float = 0.5,
                     max_backtrack: int = 40, gtol: float = 1e-8, ftol: float = 1e-14,
                     record_history: bool = False) -> OptimizeResult:
    """Steepest descent from ``x0``: central-difference gradients (one batch of 2D rows, step
    h * max(1, |x_k|)) and Armijo backtracking; projected onto ``bounds`` if given."""
    low, high = _bounds(bounds)
    o = _options(_c.DescentOptions, dict(max_iter=max_iter, h=h, t0=t0, armijo=armijo, backtrack=backtrack,
                                         max_backtrack=max_backtrack, gtol=gtol, ftol=ftol,
                                         record_history=record_history))
    return _c.steepest_descent(_objective(fun), np.asarray(x0, dtype=float), low, high, o)


def levenberg_marquardt(residuals: Callable[[np.ndarray], np.ndarray], x0, bounds: Optional[Bounds] = None, *,
                        max_iter: int = 200, h: float = 1e-6, lambda0: float = 1e-3, gtol: float = 1e-10,
                        xtol: float = 1e-12, ftol: float = 1e-15, record_history: bool = False) -> OptimizeResult:
    """Levenberg-Marquardt on 1/2 |r(x)|^2. ``residuals`` maps (N, D) -> (N, R); the Jacobian is
    taken by central differences in one batch call. ``fun`` in the result is 1/2 |r|^2."""
    if not callable(residuals):
        raise ValueError("residuals: expected a vectorised callable (N, D) -> (N, R)")
    low, high = _bounds(bounds)
    o = _options(_c.LMOptions, dict(max_iter=max_iter, h=h, lambda0=lambda0, gtol=gtol, xtol=xtol, ftol=ftol,
                                    record_history=record_history))
    return _c.levenberg_marquardt(residuals, np.asarray(x0, dtype=float), low, high, o)


def trust_region(fun: Objective, x0, bounds: Optional[Bounds] = None, *, max_iter: int = 200, h: float = 1e-6,
                 radius0: float = 1.0, max_radius: float = 1e6, eta: float = 1e-4, gtol: float = 1e-8,
                 xtol: float = 1e-12, record_history: bool = False) -> OptimizeResult:
    """Dogleg trust region with central-difference gradients and BFGS Hessian updates, for scalar
    objectives such as a negative log posterior of a pose (Eq. 4.4)."""
    low, high = _bounds(bounds)
    o = _options(_c.TrustRegionOptions, dict(max_iter=max_iter, h=h, radius0=radius0, max_radius=max_radius,
                                             eta=eta, gtol=gtol, xtol=xtol, record_history=record_history))
    return _c.trust_region(_objective(fun), np.asarray(x0, dtype=float), low, high, o)


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
