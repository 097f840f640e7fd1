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
    """Return whether a reading of the law is ``slip_limit``.

    Parameters
    ----------
    regularization
        The reading of Eq. 21 (``friction.regularization``): ``none`` (as printed) or ``slip_limit``.

    Returns
    -------
    slip_limit : bool
        True for ``slip_limit``, False for ``none`` (Eq. 21 as printed).

    Raises
    ------
    ValueError
        When ``regularization`` is neither of ``REGULARIZATIONS``.
    """
    if regularization not in REGULARIZATIONS:
        raise ValueError(
            f"friction regularization {regularization!r} is not one of {REGULARIZATIONS}: "
            "write friction.regularization: none (Eq. 21 as printed) or slip_limit"
        )
    return regularization == "slip_limit"


@njit(cache=True)
def initial_stiffness(normal_force: float, e_f: float, k_c: float) -> float:
    """Return the law's initial stiffness e_0 of Eq. 22, e_f (1 - exp(-k_c N / e_f)).

    Parameters
    ----------
    normal_force
        The total normal force N [N] (static preload and dynamic part, compression positive).
    e_f
        The law's parameter e_f, the limit of e_0 at large N [N/m].
    k_c
        The law's parameter k_c, e_0's slope over N at N = 0 [1/m].

    Returns
    -------
    e0 : float
        The initial stiffness e_0 [N/m].
    """
    return e_f * (1.0 - np.exp(-k_c * normal_force / e_f))


@njit(cache=True)
def iwan_force(
    xi: float, anchors: np.ndarray, weights: np.ndarray, e0_total: float, mu_n: float, flags: np.ndarray
) -> float:
    """Return the Iwan (Maxwell-slip) element's shear force at the slip xi.

    The element, the multi-asperity friction candidate, has n sliders of stiffness e_0 / n (Eq. 22's e_0) and slip
    limits mu N w_i (weights w_i summing to 1). A slider that would exceed its limit slips: its anchor follows xi.

    Parameters
    ----------
    xi
        The relative tangential displacement xi [m].
    anchors
        The sliders' anchor positions [m], shape (n_sliders,); updated in place where a slider slips.
    weights
        The sliders' shares w_i of the slip limit [-], shape (n_sliders,), summing to 1.
    e0_total
        The element's total stiffness e_0 [N/m], shared equally by the sliders.
    mu_n
        The element's total slip limit mu N [N].
    flags
        Int8 slip flags [-], shape (n_sliders,), or shape (0,) for none: set to 0 where the slider sticks, 1 / -1
        where it slips forwards / backwards.

    Returns
    -------
    force : float
        The element's shear force [N], the sum over the sliders.
    """
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
def slip_width(normal_force: float, e0: float, e_t: float, kappa: float, mu: float) -> float:
    """Return the slip width alpha_0 (1 - kappa e_t / e_0) = e_0 / lambda of Eq. 21, with alpha_0 = mu N.

    It is the scale of |S - e_t xi| (the slip-limit bound of the ``slip_limit`` reading).

    Parameters
    ----------
    normal_force
        The total normal force N [N].
    e0
        The initial stiffness e_0 at ``normal_force`` [N/m] (``initial_stiffness``).
    e_t
        The law's parameter e_t, the macro-slip stiffness [N/m].
    kappa
        The law's parameter kappa [-].
    mu
        The friction coefficient mu [-].

    Returns
    -------
    width : float
        The slip width [N].
    """
    return mu * normal_force * (1.0 - kappa * e_t / e0)


@njit(cache=True)
def valanis_slope(
    S: float,
    xi: float,
    direction: float,
    normal_force: float,
    e_f: float,
    k_c: float,
    e_t: float,
    kappa: float,
    mu: float,
) -> float:
    """Return the slope dS/dxi of Eq. 21.

    Parameters
    ----------
    S
        The friction force S [N].
    xi
        The relative tangential displacement xi [m].
    direction
        The motion's direction sgn(xi'), +1 or -1 [-].
    normal_force
        The total normal force N [N].
    e_f
        The law's parameter e_f [N/m].
    k_c
        The law's parameter k_c [1/m].
    e_t
        The law's parameter e_t [N/m].
    kappa
        The law's parameter kappa [-].
    mu
        The friction coefficient mu [-].

    Returns
    -------
    slope : float
        dS/dxi [N/m].
    """
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
    """Return S with d >= -SINGULAR_GUARD / kappa (Eq. 21 as printed, away from its singular point)."""
    if kappa <= 0.0:
        return S
    lim = SINGULAR_GUARD * width / kappa  # direction (S - e_t xi) <= lim
    ahead = direction * (S - e_t * xi)
    if ahead > lim:
        return e_t * xi + direction * lim
    return S


@njit(cache=True)
def _step_terms(S, xi0, xi1, e0a, wa, e0b, wb, e_t, kappa, slip_limit):
    """Return S after xi moves from xi0 to xi1, with e_0 and the slip width given at both ends.

    Heun's method in xi, e_0 and the slip width linear over the step.
    """
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
def valanis_step(
    S: float,
    xi0: float,
    xi1: float,
    n0: float,
    n1: float,
    e_f: float,
    k_c: float,
    e_t: float,
    kappa: float,
    mu: float,
    n_min: float,
    slip_limit: bool,
) -> float:
    """Return the friction force S after xi moves from xi0 to xi1 while N moves from n0 to n1 (Eqs. 21-22).

    Heun's method in xi, N linear over the step. Where either normal force is at or below ``n_min`` the contact is
    open, or closes again and sticks where it lands: S is 0.

    Parameters
    ----------
    S
        The friction force at the step's start [N].
    xi0
        The relative tangential displacement at the step's start [m].
    xi1
        The relative tangential displacement at the step's end [m].
    n0
        The total normal force at the step's start [N].
    n1
        The total normal force at the step's end [N].
    e_f
        The law's parameter e_f [N/m].
    k_c
        The law's parameter k_c [1/m].
    e_t
        The law's parameter e_t [N/m].
    kappa
        The law's parameter kappa [-].
    mu
        The friction coefficient mu [-].
    n_min
        The normal force at or below which the contact is open [N].
    slip_limit
        The ``slip_limit`` reading (True) or Eq. 21 as printed (False).

    Returns
    -------
    S : float
        The friction force at the step's end [N].
    """
    if n1 <= n_min or n0 <= n_min:  # open, or re-contact: the contact sticks where it lands
        return 0.0
    e0a = initial_stiffness(n0, e_f, k_c)
    e0b = initial_stiffness(n1, e_f, k_c)
    return valanis_step_at(S, xi0, xi1, n0, n1, e0a, e0b, e_t, kappa, mu, slip_limit)


@njit(cache=True)
def valanis_step_at(
    S: float,
    xi0: float,
    xi1: float,
    n0: float,
    n1: float,
    e0a: float,
    e0b: float,
    e_t: float,
    kappa: float,
    mu: float,
    slip_limit: bool,
) -> float:
    """Return ``valanis_step``'s friction force with Eq. 22's e_0 given at both ends of the step.

    A time stepper that carries one step's e0b over as the next step's e0a saves an exponential a step. Both normal
    forces must be above n_min (the contact closed): this step does not check it.

    Parameters
    ----------
    S
        The friction force at the step's start [N].
    xi0
        The relative tangential displacement at the step's start [m].
    xi1
        The relative tangential displacement at the step's end [m].
    n0
        The total normal force at the step's start [N].
    n1
        The total normal force at the step's end [N].
    e0a
        Eq. 22's e_0 at ``n0`` [N/m].
    e0b
        Eq. 22's e_0 at ``n1`` [N/m].
    e_t
        The law's parameter e_t [N/m].
    kappa
        The law's parameter kappa [-].
    mu
        The friction coefficient mu [-].
    slip_limit
        The ``slip_limit`` reading (True) or Eq. 21 as printed (False).

    Returns
    -------
    S : float
        The friction force at the step's end [N].
    """
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
    """Validate an array of the law's parameter sets and return it as a 2-D float array.

    Parameters
    ----------
    params
        Parameter sets, rows (e_f, k_c, e_t, kappa, mu) [N/m, 1/m, N/m, -, -], shape (n_sets, 5), or (5,) for one.

    Returns
    -------
    params : np.ndarray
        The same sets as floats [N/m, 1/m, N/m, -, -], shape (n_sets, 5).

    Raises
    ------
    ValueError
        When the array is not of shape (n_sets, 5), holds no set, or a set breaks a rule (all finite, e_f, k_c and
        mu positive, e_t non-negative, kappa in [0, 1)); the message names the first invalid set and its rule.
    """
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
    """Return ``valanis_step`` run in plain Python (the jitted step's own Python source)."""
    return valanis_step.py_func(S, xi0, xi1, n0, n1, e_f, k_c, e_t, kappa, mu, n_min, slip_limit)


def valanis_friction_force_reference(
    xi: np.ndarray,
    normal_force: np.ndarray,
    params: np.ndarray,
    tol: float = 1e-7,
    max_periods: int = 200,
    n_min: float = 1e-6,
    regularization: str = "none",
) -> np.ndarray:
    """Return :func:`valanis_friction_force`'s friction force computed by a plain reference implementation.

    A Python loop per sample and parameter set, used to test the fast kernel. Invalid parameters, an empty
    population, non-finite signals or a normal force at or below ``n_min`` raise ValueError (in
    ``check_parameters`` and the signals' check).

    Parameters
    ----------
    xi
        The relative tangential displacement [m], shape (n_samples,), over a whole number of periods.
    normal_force
        The total normal force [N], shape (n_samples,), compression positive, static preload included.
    params
        Parameter sets, rows (e_f, k_c, e_t, kappa, mu) [N/m, 1/m, N/m, -, -], shape (n_sets, 5).
    tol
        The periods repeat until S changes by less than ``tol`` x max |S| over a period [-].
    max_periods
        The most periods repeated.
    n_min
        The normal force at or below which the contact is open [N].
    regularization
        The reading of Eq. 21: ``none`` or ``slip_limit``.

    Returns
    -------
    S : np.ndarray
        The friction force at periodic steady state [N], shape (n_sets, n_samples).
    """
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
    """Run valanis_step per sample with the normal-force terms (e_0 and the slip width) precomputed per sample.

    For each set: the same arithmetic, one exp per sample.
    """
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
    xi: np.ndarray,
    normal_force: np.ndarray,
    params: np.ndarray,
    tol: float = 1e-7,
    max_periods: int = 200,
    n_min: float = 1e-6,
    return_periods: bool = False,
    regularization: str = "none",
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Return the friction force S of the modified Valanis law (Eqs. 21-22) at periodic steady state.

    The law is stepped once per sample with Heun's method in xi: the samples must resolve the
    motion (about 256 per period give 0.5 % of max |S|; refine the grid by Fourier
    interpolation first). Periods are repeated from S = 0 until S changes by less than
    ``tol`` x max |S| over a period (at most ``max_periods``). Sets are evaluated in parallel.
    Invalid parameters, an empty population, non-finite signals, or a normal force at or below ``n_min`` (the
    contact opens) raise ValueError (in ``check_parameters``, ``slip_limit_flag`` and the signals' check).

    Parameters
    ----------
    xi
        The relative tangential displacement [m], shape (n_samples,), over a whole number of periods (periodic:
        the last sample is followed by the first).
    normal_force
        The total normal force N [N], shape (n_samples,), compression positive, static preload included.
    params
        Parameter sets, rows (e_f, k_c, e_t, kappa, mu) [N/m, 1/m, N/m, -, -], shape (n_sets, 5).
    tol
        The periods repeat until S changes by less than ``tol`` x max |S| over a period [-].
    max_periods
        The most periods repeated.
    n_min
        The normal force at or below which the contact is open [N]; the signals must stay above it.
    return_periods
        Whether to return the periods each set took too.
    regularization
        ``none`` (Eq. 21 as printed, guarded only at its singular point) or ``slip_limit`` (see the module's
        docstring).

    Returns
    -------
    S : np.ndarray
        The friction force [N], shape (n_sets, n_samples); alone unless ``return_periods``.
    periods : np.ndarray
        With ``return_periods``: the periods each set was stepped [cycles], shape (n_sets,), int64.
    """
    xi, n = _check_signals(xi, normal_force, n_min)
    p = np.ascontiguousarray(check_parameters(params))
    slip_limit = slip_limit_flag(regularization)
    out = np.zeros((p.shape[0], xi.size))
    periods = np.zeros(p.shape[0], dtype=np.int64)
    _population_kernel(xi, n, p, float(tol), int(max_periods), float(n_min), slip_limit, out, periods)
    return (out, periods) if return_periods else out
