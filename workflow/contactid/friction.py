"""The modified Valanis friction law (Eqs. 21-22).

    dS/dxi = e_0 [1 + (lambda/e_0) sgn(xi') (e_t xi - S)] / [1 + kappa (lambda/e_0) sgn(xi') (e_t xi - S)]
    lambda = e_0 / (alpha_0 (1 - kappa e_t / e_0)),  alpha_0 = mu N,  e_0 = e_f (1 - exp(-k_c N / e_f))

with N the total normal force (static preload + dynamic part, compression positive) and xi the
relative tangential displacement (Eq. 9). The law is rate independent: S changes only with xi,
along the direction sgn(dxi).

Regularisation (documented): where N <= ``n_min`` the contact carries no friction (S = 0, the
contact is open); and |S - e_t xi| is kept at most alpha_0 (1 - kappa e_t / e_0), the law's own
macro-slip asymptote, so that a falling normal force makes the contact slip back to the
friction limit. Within that bound the denominator stays >= 1 - kappa > 0 for kappa < 1.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True)
def valanis_slope(S, xi, direction, normal_force, e_f, k_c, e_t, kappa, mu):
    """dS/dxi (N/m) of Eq. 21 at friction force S (N), displacement xi (m), motion
    direction +-1 and total normal force N (N)."""
    e0 = e_f * (1.0 - np.exp(-k_c * normal_force / e_f))  # Eq. 22
    alpha0 = mu * normal_force
    ratio = 1.0 / (alpha0 * (1.0 - kappa * e_t / e0))  # lambda / e_0
    d = ratio * direction * (e_t * xi - S)
    return e0 * (1.0 + d) / (1.0 + kappa * d)


@njit(cache=True)
def _clamp_to_slip_limit(S, xi, normal_force, e_f, k_c, e_t, kappa, mu):
    e0 = e_f * (1.0 - np.exp(-k_c * normal_force / e_f))
    lim = mu * normal_force * (1.0 - kappa * e_t / e0)
    base = e_t * xi
    return min(max(S, base - lim), base + lim)


@njit(cache=True)
def valanis_step(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min):
    """Friction force after xi moves from xi0 to xi1 while N moves from n0 to n1
    (Heun's method in xi; N linear over the step). Returns S (N)."""
    if n1 <= n_min:
        return 0.0
    if n0 <= n_min:  # re-contact: the contact sticks where it lands
        return 0.0
    dxi = xi1 - xi0
    if dxi == 0.0:
        return _clamp_to_slip_limit(S, xi1, n1, e_f, k_c, e_t, kappa, mu)
    direction = 1.0 if dxi > 0.0 else -1.0
    S = _clamp_to_slip_limit(S, xi0, n0, e_f, k_c, e_t, kappa, mu)
    k1 = valanis_slope(S, xi0, direction, n0, e_f, k_c, e_t, kappa, mu)
    s_pred = _clamp_to_slip_limit(S + k1 * dxi, xi1, n1, e_f, k_c, e_t, kappa, mu)
    k2 = valanis_slope(s_pred, xi1, direction, n1, e_f, k_c, e_t, kappa, mu)
    return _clamp_to_slip_limit(S + 0.5 * (k1 + k2) * dxi, xi1, n1, e_f, k_c, e_t, kappa, mu)


PARAMETER_NAMES = ("e_f", "k_c", "e_t", "kappa", "mu")
PARAMETER_UNITS = ("N/m", "1/m", "N/m", "1", "1")


def check_parameters(params: np.ndarray) -> np.ndarray:
    """Validate a (n_sets, 5) parameter array (e_f, k_c, e_t, kappa, mu); raise ValueError
    naming the first invalid set and the rule it breaks."""
    p = np.atleast_2d(np.asarray(params, dtype=float))
    if p.ndim != 2 or p.shape[1] != 5:
        raise ValueError(f"params must have shape (n_sets, 5) in the order {PARAMETER_NAMES}, got {p.shape}")
    if p.shape[0] == 0:
        raise ValueError("params holds no parameter set (empty population)")
    rules = (
        (~np.isfinite(p).all(axis=1), "all five parameters must be finite"),
        (p[:, 0] <= 0, "e_f must be positive"),
        (p[:, 1] <= 0, "k_c must be positive"),
        (p[:, 2] < 0, "e_t must be non-negative"),
        ((p[:, 3] < 0) | (p[:, 3] >= 1), "kappa must lie in [0, 1)"),
        (p[:, 4] <= 0, "mu must be positive"),
    )
    for bad, rule in rules:
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"parameter set {i} {dict(zip(PARAMETER_NAMES, p[i]))}: {rule}")
    return p


def _check_signals(xi, normal_force, n_min):
    xi = np.ascontiguousarray(xi, dtype=float)
    n = np.ascontiguousarray(normal_force, dtype=float)
    if xi.ndim != 1 or n.shape != xi.shape or xi.size < 4:
        raise ValueError("xi and normal_force must be 1-D arrays of the same length (at least 4 samples)")
    if not (np.isfinite(xi).all() and np.isfinite(n).all()):
        raise ValueError("xi or normal_force holds NaN or infinite samples")
    if np.min(n) <= n_min:
        raise ValueError(f"the normal force reaches {np.min(n):.3g} N <= {n_min:g} N: the contact opens, where the "
                         "law carries no friction (S = 0); the periodic friction force is not defined by Eq. 21 there")
    return xi, n


def _step_python(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min):
    """The per-sample step in plain Python (the jitted step's own Python source)."""
    return valanis_step.py_func(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min)


def valanis_friction_force_reference(xi, normal_force, params, tol: float = 1e-7, max_periods: int = 200,
                                     n_min: float = 1e-6) -> np.ndarray:
    """Plain reference implementation of :func:`valanis_friction_force` (a Python loop per
    sample and parameter set), used to test the fast kernel."""
    xi, n = _check_signals(xi, normal_force, n_min)
    p = check_parameters(params)
    out = np.empty((p.shape[0], xi.size))
    for k, row in enumerate(p):
        e_f, k_c, e_t, kappa, mu = (float(v) for v in row)
        S = 0.0
        prev = None
        for _ in range(max_periods):
            cur = np.empty(xi.size)
            for i in range(xi.size):
                j = i - 1  # wraps to the last sample: the signals are periodic
                S = _step_python(S, xi[j], xi[i], n[j], n[i], e_f, k_c, e_t, kappa, mu, n_min)
                cur[i] = S
            if prev is not None and np.max(np.abs(cur - prev)) <= tol * max(np.max(np.abs(cur)), 1e-300):
                break
            prev = cur
        out[k] = cur
    return out


@njit(cache=True)
def _slope_pre(S, xi, direction, e0, ratio, e_t, kappa):
    d = ratio * direction * (e_t * xi - S)
    return e0 * (1.0 + d) / (1.0 + kappa * d)


@njit(parallel=True, cache=True)
def _population_kernel(xi, n, p, tol, max_periods, n_min, out, periods_used):
    """valanis_step per sample with the normal-force terms (e_0, lambda/e_0 and the slip
    limit) precomputed per sample for each set: the same arithmetic, one exp per sample."""
    n_sets = p.shape[0]
    m = xi.size
    for k in prange(n_sets):
        e_f, k_c, e_t, kappa, mu = p[k, 0], p[k, 1], p[k, 2], p[k, 3], p[k, 4]
        e0 = np.empty(m)
        ratio = np.empty(m)
        lim = np.empty(m)
        for i in range(m):
            e0[i] = e_f * (1.0 - np.exp(-k_c * n[i] / e_f))
            ratio[i] = 1.0 / (mu * n[i] * (1.0 - kappa * e_t / e0[i]))
            lim[i] = mu * n[i] * (1.0 - kappa * e_t / e0[i])
        S = 0.0
        used = max_periods
        for period in range(max_periods):
            change = 0.0
            peak = 0.0
            for i in range(m):
                j = i - 1 if i > 0 else m - 1
                dxi = xi[i] - xi[j]
                # clamp the start to the slip limit at xi[j] (as valanis_step does)
                base = e_t * xi[j]
                S = min(max(S, base - lim[j]), base + lim[j])
                if dxi != 0.0:
                    direction = 1.0 if dxi > 0.0 else -1.0
                    k1 = _slope_pre(S, xi[j], direction, e0[j], ratio[j], e_t, kappa)
                    base1 = e_t * xi[i]
                    sp = min(max(S + k1 * dxi, base1 - lim[i]), base1 + lim[i])
                    k2 = _slope_pre(sp, xi[i], direction, e0[i], ratio[i], e_t, kappa)
                    S = S + 0.5 * (k1 + k2) * dxi
                base1 = e_t * xi[i]
                S = min(max(S, base1 - lim[i]), base1 + lim[i])
                d = abs(S - out[k, i])
                if d > change:
                    change = d
                if abs(S) > peak:
                    peak = abs(S)
                out[k, i] = S
            if period > 0 and change <= tol * peak:
                used = period + 1
                break
        periods_used[k] = used


def valanis_friction_force(xi, normal_force, params, tol: float = 1e-7, max_periods: int = 200,
                           n_min: float = 1e-6, return_periods: bool = False):
    """Friction force S (N) of the modified Valanis law (Eqs. 21-22) at periodic steady state.

    xi: (n_samples,) tangential motion (m) over a whole number of periods (periodic: the last
    sample is followed by the first); normal_force: (n_samples,) total normal force N (N),
    compression positive, static preload included; params: (n_sets, 5) rows (e_f, k_c, e_t,
    kappa, mu) in N/m, 1/m, N/m, -, -. Returns S of shape (n_sets, n_samples).

    The law is stepped once per sample with Heun's method in xi: the samples must resolve the
    motion (about 256 per period give 0.5 % of max |S|; refine the grid by Fourier
    interpolation first). Periods are repeated from S = 0 until S changes by less than
    ``tol`` x max |S| over a period (at most ``max_periods``). Sets are evaluated in parallel.
    Raises ValueError for invalid parameters, an empty population, non-finite signals, or a
    normal force at or below ``n_min`` (the contact opens).
    """
    xi, n = _check_signals(xi, normal_force, n_min)
    p = np.ascontiguousarray(check_parameters(params))
    out = np.zeros((p.shape[0], xi.size))
    periods = np.zeros(p.shape[0], dtype=np.int64)
    _population_kernel(xi, n, p, float(tol), int(max_periods), float(n_min), out, periods)
    return (out, periods) if return_periods else out
