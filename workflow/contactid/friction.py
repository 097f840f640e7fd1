"""The modified Valanis friction law (Eqs. 21-22).

    dS/dxi = e_0 [1 + (lambda/e_0) sgn(xi') (e_t xi - S)] / [1 + kappa (lambda/e_0) sgn(xi') (e_t xi - S)]
    lambda = e_0 / (alpha_0 (1 - kappa e_t / e_0)),  alpha_0 = mu N,  e_0 = e_f (1 - exp(-k_c N / e_f))

with N the total normal force (static preload + dynamic part, compression positive) and xi the
relative tangential displacement (Eq. 9). The law is rate independent: S changes only with xi,
along the direction sgn(dxi).

Two readings of the law, chosen by ``friction.regularization`` (and ``rig.truth.friction.regularization``
for the virtual rig's truth):

- ``none`` (default): Eq. 21 as printed. When N falls, |S - e_t xi| may exceed the law's macro-slip
  asymptote; S then relaxes back along xi as the contact moves (dS/dxi has the opposite sign of
  dxi), and stays where it is while xi does not move. The law is singular where its denominator
  vanishes, at d = (lambda/e_0) sgn(xi') (e_t xi - S) = -1/kappa (|S - e_t xi| about 3.5 alpha_0 for
  kappa = 0.28); only there is it guarded: d is kept at or above -SINGULAR_GUARD/kappa. Where Eq. 21
  is stiff (near that point) a step is split into sub-steps.
- ``slip_limit``: |S - e_t xi| is kept at most alpha_0 (1 - kappa e_t / e_0), so that a falling
  normal force makes the contact slip back to the friction limit at once, even without motion
  (the kernel of issues 2-14). Within that bound the denominator stays >= 1 - kappa > 0.

Both: where N <= ``n_min`` the contact carries no friction (S = 0, the contact is open), and a
contact that closes again sticks where it lands.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .friction_parameters import PARAMETER_NAMES

REGULARIZATIONS = ("none", "slip_limit")
SINGULAR_GUARD = 0.9  # law "none": d >= -SINGULAR_GUARD / kappa (Eq. 21's denominator >= 1 - SINGULAR_GUARD)
STIFF_STEP = 0.5  # law "none": largest |d(dS)/dS| per (sub-)step; beyond it the step is split (Heun is stable to 2)
MAX_SUBSTEPS = 256


def slip_limit_flag(regularization: str) -> bool:
    """True for ``slip_limit``, False for ``none`` (Eq. 21 as printed); ValueError for anything else."""
    if regularization not in REGULARIZATIONS:
        raise ValueError(
            f"friction regularization {regularization!r} is not one of {REGULARIZATIONS}: "
            "write friction.regularization: none (Eq. 21 as printed) or slip_limit"
        )
    return regularization == "slip_limit"


@njit(cache=True)
def initial_stiffness(normal_force, e_f, k_c):
    """e_0 (N/m), Eq. 22: e_f (1 - exp(-k_c N / e_f)) at total normal force N (N)."""
    return e_f * (1.0 - np.exp(-k_c * normal_force / e_f))


@njit(cache=True)
def iwan_force(xi, anchors, weights, e0_total, mu_n, flags):
    """The Iwan (Maxwell-slip) element's shear force (N) at the slip xi (m): n sliders of stiffness e_0 / n (Eq. 22's
    e_0, N/m) and slip limits mu N w_i (weights w_i summing to 1), the multi-asperity friction candidate. A slider
    that would exceed its limit slips: its anchor (m, ``anchors``, updated in place) follows xi. ``flags`` (int8,
    one per slider, or empty): set to 0 where the slider sticks, 1 / -1 where it slips forwards / backwards."""
    total = 0.0
    n = weights.size
    for i in range(n):
        k = e0_total / n
        lim = mu_n * weights[i]
        f = k * (xi - anchors[i])
        flag = 0
        if f > lim:
            anchors[i] = xi - lim / k
            f = lim
            flag = 1
        elif f < -lim:
            anchors[i] = xi + lim / k
            f = -lim
            flag = -1
        if flags.size:
            flags[i] = flag
        total += f
    return total


@njit(cache=True)
def slip_width(normal_force, e0, e_t, kappa, mu):
    """alpha_0 (1 - kappa e_t / e_0) = e_0 / lambda (N), Eq. 21, with alpha_0 = mu N: the scale of
    |S - e_t xi| (the slip-limit bound of the ``slip_limit`` reading)."""
    return mu * normal_force * (1.0 - kappa * e_t / e0)


@njit(cache=True)
def valanis_slope(S, xi, direction, normal_force, e_f, k_c, e_t, kappa, mu):
    """dS/dxi (N/m) of Eq. 21 at friction force S (N), displacement xi (m), motion
    direction +-1 and total normal force N (N)."""
    e0 = initial_stiffness(normal_force, e_f, k_c)  # Eq. 22
    return _slope(S, xi, direction, e0, slip_width(normal_force, e0, e_t, kappa, mu), e_t, kappa)


@njit(cache=True)
def _slope(S, xi, direction, e0, width, e_t, kappa):
    d = direction * (e_t * xi - S) / width  # (lambda / e_0) sgn(xi') (e_t xi - S)
    return e0 * (1.0 + d) / (1.0 + kappa * d)  # Eq. 21


@njit(cache=True)
def _clamp(S, xi, width, e_t):
    base = e_t * xi
    return min(max(S, base - width), base + width)


@njit(cache=True)
def _guard(S, xi, direction, width, e_t, kappa):
    """S with d >= -SINGULAR_GUARD / kappa (Eq. 21 as printed, away from its singular point)."""
    if kappa <= 0.0:
        return S
    lim = SINGULAR_GUARD * width / kappa  # direction (S - e_t xi) <= lim
    ahead = direction * (S - e_t * xi)
    if ahead > lim:
        return e_t * xi + direction * lim
    return S


@njit(cache=True)
def _step_terms(S, xi0, xi1, e0a, wa, e0b, wb, e_t, kappa, slip_limit):
    """S after xi moves from xi0 to xi1, with e_0 and the slip width at both ends (Heun's method in
    xi; both linear over the step)."""
    dxi = xi1 - xi0
    if slip_limit:
        S = _clamp(S, xi0, wa, e_t)
        if dxi != 0.0:
            direction = 1.0 if dxi > 0.0 else -1.0
            k1 = _slope(S, xi0, direction, e0a, wa, e_t, kappa)
            sp = _clamp(S + k1 * dxi, xi1, wb, e_t)
            k2 = _slope(sp, xi1, direction, e0b, wb, e_t, kappa)
            S = S + 0.5 * (k1 + k2) * dxi
        return _clamp(S, xi1, wb, e_t)
    if dxi == 0.0:
        return S
    direction = 1.0 if dxi > 0.0 else -1.0
    S = _guard(S, xi0, direction, wa, e_t, kappa)
    q = 1.0 + kappa * direction * (e_t * xi0 - S) / wa
    stiff = e0a * (1.0 - kappa) * abs(dxi) / (wa * q * q)  # |d(dS)/dS| of one Heun step
    m = 1
    if stiff > STIFF_STEP:
        m = min(int(stiff / STIFF_STEP) + 1, MAX_SUBSTEPS)
    h = dxi / m
    for s in range(m):
        fa = s / m
        fb = (s + 1) / m
        xa = xi0 + fa * dxi
        xb = xi0 + fb * dxi
        e0s = e0a + fa * (e0b - e0a)
        ws = wa + fa * (wb - wa)
        e0e = e0a + fb * (e0b - e0a)
        we = wa + fb * (wb - wa)
        k1 = _slope(S, xa, direction, e0s, ws, e_t, kappa)
        sp = _guard(S + k1 * h, xb, direction, we, e_t, kappa)
        k2 = _slope(sp, xb, direction, e0e, we, e_t, kappa)
        S = _guard(S + 0.5 * (k1 + k2) * h, xb, direction, we, e_t, kappa)
    return S


@njit(cache=True)
def valanis_step(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min, slip_limit):
    """Friction force S (N) after xi moves from xi0 to xi1 (m) while N moves from n0 to n1 (N),
    Eqs. 21-22 (Heun's method in xi; N linear over the step). slip_limit: the ``slip_limit``
    reading (True) or Eq. 21 as printed (False)."""
    if n1 <= n_min or n0 <= n_min:  # open, or re-contact: the contact sticks where it lands
        return 0.0
    e0a = initial_stiffness(n0, e_f, k_c)
    e0b = initial_stiffness(n1, e_f, k_c)
    return valanis_step_at(S, xi0, xi1, n0, n1, e0a, e0b, e_t, kappa, mu, slip_limit)


@njit(cache=True)
def valanis_step_at(S, xi0, xi1, n0, n1, e0a, e0b, e_t, kappa, mu, slip_limit):
    """``valanis_step`` with Eq. 22's e_0 at both ends given (e0a at n0, e0b at n1, N/m; a time stepper that
    carries one step's e0b over as the next step's e0a saves an exponential a step); both forces above n_min."""
    return _step_terms(
        S,
        xi0,
        xi1,
        e0a,
        slip_width(n0, e0a, e_t, kappa, mu),
        e0b,
        slip_width(n1, e0b, e_t, kappa, mu),
        e_t,
        kappa,
        slip_limit,
    )


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
        raise ValueError(
            f"the normal force reaches {np.min(n):.3g} N <= {n_min:g} N: the contact opens, where the "
            "law carries no friction (S = 0); the periodic friction force is not defined by Eq. 21 there"
        )
    return xi, n


def _step_python(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min, slip_limit):
    """The per-sample step in plain Python (the jitted step's own Python source)."""
    return valanis_step.py_func(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min, slip_limit)


def valanis_friction_force_reference(
    xi,
    normal_force,
    params,
    tol: float = 1e-7,
    max_periods: int = 200,
    n_min: float = 1e-6,
    regularization: str = "none",
) -> np.ndarray:
    """Plain reference implementation of :func:`valanis_friction_force` (a Python loop per
    sample and parameter set), used to test the fast kernel."""
    xi, n = _check_signals(xi, normal_force, n_min)
    p = check_parameters(params)
    slip_limit = slip_limit_flag(regularization)
    out = np.empty((p.shape[0], xi.size))
    for k, row in enumerate(p):
        e_f, k_c, e_t, kappa, mu = (float(v) for v in row)
        S = 0.0
        prev = None
        for _ in range(max_periods):
            cur = np.empty(xi.size)
            for i in range(xi.size):
                j = i - 1  # wraps to the last sample: the signals are periodic
                S = _step_python(S, xi[j], xi[i], n[j], n[i], e_f, k_c, e_t, kappa, mu, n_min, slip_limit)
                cur[i] = S
            if prev is not None and np.max(np.abs(cur - prev)) <= tol * max(np.max(np.abs(cur)), 1e-300):
                break
            prev = cur
        out[k] = cur
    return out


@njit(parallel=True, cache=True)
def _population_kernel(xi, n, p, tol, max_periods, n_min, slip_limit, out, periods_used):
    """valanis_step per sample with the normal-force terms (e_0 and the slip width) precomputed per
    sample for each set: the same arithmetic, one exp per sample."""
    n_sets = p.shape[0]
    m = xi.size
    for k in prange(n_sets):
        e_f, k_c, e_t, kappa, mu = p[k, 0], p[k, 1], p[k, 2], p[k, 3], p[k, 4]
        e0 = np.empty(m)
        width = np.empty(m)
        for i in range(m):
            e0[i] = initial_stiffness(n[i], e_f, k_c)
            width[i] = slip_width(n[i], e0[i], e_t, kappa, mu)
        S = 0.0
        used = max_periods
        for period in range(max_periods):
            change = 0.0
            peak = 0.0
            for i in range(m):
                j = i - 1 if i > 0 else m - 1
                S = _step_terms(S, xi[j], xi[i], e0[j], width[j], e0[i], width[i], e_t, kappa, slip_limit)
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


def valanis_friction_force(
    xi,
    normal_force,
    params,
    tol: float = 1e-7,
    max_periods: int = 200,
    n_min: float = 1e-6,
    return_periods: bool = False,
    regularization: str = "none",
):
    """Friction force S (N) of the modified Valanis law (Eqs. 21-22) at periodic steady state.

    xi: (n_samples,) tangential motion (m) over a whole number of periods (periodic: the last
    sample is followed by the first); normal_force: (n_samples,) total normal force N (N),
    compression positive, static preload included; params: (n_sets, 5) rows (e_f, k_c, e_t,
    kappa, mu) in N/m, 1/m, N/m, -, -. Returns S of shape (n_sets, n_samples).

    The law is stepped once per sample with Heun's method in xi: the samples must resolve the
    motion (about 256 per period give 0.5 % of max |S|; refine the grid by Fourier
    interpolation first). Periods are repeated from S = 0 until S changes by less than
    ``tol`` x max |S| over a period (at most ``max_periods``). Sets are evaluated in parallel.
    regularization: ``none`` (Eq. 21 as printed, guarded only at its singular point) or
    ``slip_limit`` (see the module's docstring).
    Raises ValueError for invalid parameters, an empty population, non-finite signals, or a
    normal force at or below ``n_min`` (the contact opens).
    """
    xi, n = _check_signals(xi, normal_force, n_min)
    p = np.ascontiguousarray(check_parameters(params))
    slip_limit = slip_limit_flag(regularization)
    out = np.zeros((p.shape[0], xi.size))
    periods = np.zeros(p.shape[0], dtype=np.int64)
    _population_kernel(xi, n, p, float(tol), int(max_periods), float(n_min), slip_limit, out, periods)
    return (out, periods) if return_periods else out
