"""The contact laws along one periodic path of the rig as numba kernels: stepped until they repeat, and linearised.

Harmonic balance's time-domain half (``rig.harmonic_balance``, alternating frequency/time): on the integrator's M
steps of one period, ``periodic_friction`` steps the friction law (the modified Valanis law with the Iwan share) with
the integrator's own step around the loop until it repeats and ``normal_path`` evaluates the normal law with its
tangents; ``friction_tangents`` differentiates the friction step along the converged path and ``propagate`` and
``iwan_propagate`` solve the linearised recurrences periodically, for the Newton Jacobian. Every kernel is
``@njit(cache=True)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..friction import initial_stiffness, iwan_force, valanis_step
from .integrator import normal_force


@njit(cache=True)
def periodic_friction(
    xi: np.ndarray,
    N_from: np.ndarray,
    N: np.ndarray,
    fr: np.ndarray,
    n_min: float,
    iw_share: float,
    iw_w: np.ndarray,
    tol: float,
    max_periods: int,
    S_out: np.ndarray,
    S_val_out: np.ndarray,
    iw_x: np.ndarray,
    iw_flag: np.ndarray,
) -> None:
    """Step the friction law along a periodic path on the integrator's steps until it repeats.

    Step i moves xi[i-1] -> xi[i] while N moves N_from[i] -> N[i] (the integrator's pair: the last step's final normal
    force and this step's explicit estimate). The Valanis state is stepped with the integrator's ``valanis_step``
    around the loop until it repeats (change below tol x max|S|), the Iwan share's sliders as the integrator's
    ``friction.iwan_force`` steps them; S_val_out the Valanis state, S_out (1 - s) S_val + s S_iwan (zero where N <= 0,
    the contact open); iw_x (M, sliders) the anchors after each step and iw_flag how each slider moved (0 stuck, +1 / -1
    slipping, 2 reset by an open contact).

    Parameters
    ----------
    xi
        The tangential displacement xi along the path [m], shape (M,).
    N_from
        The normal force at each step's start (the last step's final normal force) [N], shape (M,).
    N
        The normal force at each step's end (this step's explicit estimate) [N], shape (M,).
    fr
        The friction law's record (``rig.nonlinear.friction_record``) [N/m, 1/m, N/m, -, -, -], shape (6,).
    n_min
        The normal force at or below which the contact is open [N].
    iw_share
        The Iwan element's share s of the friction force [-].
    iw_w
        The Iwan sliders' slip limits as fractions of mu N (``rig.nonlinear.iwan_slip_weights``) [-],
        shape (n_sliders,).
    tol
        The change, relative to max|S|, below which the loop repeats [-].
    max_periods
        The most periods stepped around the loop.
    S_out
        Output: the friction force S [N], shape (M,).
    S_val_out
        Output: the Valanis state [N], shape (M,).
    iw_x
        Output: the Iwan sliders' anchors after each step [m], shape (M, n_sliders).
    iw_flag
        Output: how each slider moved on each step (0 stuck, +1 / -1 slipping, 2 reset) [-], shape (M, n_sliders).
    """
    e_f, k_c, e_t, kappa, mu, slip_limit = fr[0], fr[1], fr[2], fr[3], fr[4], fr[5] > 0.5
    m = xi.size
    n_sl = iw_w.size
    x_sl = np.zeros(n_sl)
    S = 0.0
    for period in range(max_periods):
        change = 0.0
        peak = 0.0
        for i in range(m):
            j = i - 1 if i > 0 else m - 1
            S = valanis_step(S, xi[j], xi[i], N_from[i], N[i], e_f, k_c, e_t, kappa, mu, n_min, slip_limit)
            s_iw = 0.0
            if iw_share > 0.0:
                if N[i] > 0.0:
                    s_iw = iwan_force(xi[i], x_sl, iw_w, initial_stiffness(N[i], e_f, k_c), mu * N[i], iw_flag[i])
                    for q in range(n_sl):
                        iw_x[i, q] = x_sl[q]
                else:
                    for q in range(n_sl):
                        x_sl[q] = xi[i]
                        iw_x[i, q] = xi[i]
                        iw_flag[i, q] = 2
            tot = (1.0 - iw_share) * S + iw_share * s_iw if N[i] > 0.0 else 0.0
            d = abs(tot - S_out[i])
            if d > change:
                change = d
            if abs(tot) > peak:
                peak = abs(tot)
            S_out[i] = tot
            S_val_out[i] = S
        if period > 0 and change <= tol * max(peak, 1e-300):
            break


@njit(cache=True)
def iwan_propagate(
    xi: np.ndarray,
    N: np.ndarray,
    iw_x: np.ndarray,
    iw_flag: np.ndarray,
    iw_w: np.ndarray,
    e_f: float,
    k_c: float,
    mu: float,
    dxi: np.ndarray,
    dN: np.ndarray,
    out: np.ndarray,
) -> None:
    """Linearise the Iwan element periodically along the path (see ``periodic_friction``).

    For every column, the change of its force dS (M, n_cols) from changes of xi and of N (the sliders' stiffness
    e_0(N) / n and limits mu N w_q), with each slider's memory of its anchor (kept while it sticks, reset where it slips
    or the contact opens).

    Parameters
    ----------
    xi
        The tangential displacement xi along the path [m], shape (M,).
    N
        The normal force the sliders see on each step (the explicit estimate) [N], shape (M,).
    iw_x
        The sliders' anchors after each step (``periodic_friction``) [m], shape (M, n_sliders).
    iw_flag
        How each slider moved on each step (``periodic_friction``) [-], shape (M, n_sliders).
    iw_w
        The sliders' slip limits as fractions of mu N [-], shape (n_sliders,).
    e_f
        The friction law's parameter e_f [N/m].
    k_c
        The friction law's parameter k_c [1/m].
    mu
        The friction coefficient mu [-].
    dxi
        Changes of xi, one column per perturbation [m], shape (M, n_cols).
    dN
        Changes of N, one column per perturbation [N], shape (M, n_cols).
    out
        Output: the changes dS of the Iwan element's force [N], shape (M, n_cols).
    """
    m, n_cols = dxi.shape
    n_sl = iw_w.size
    for i in range(m):
        for c in range(n_cols):
            out[i, c] = 0.0
    dx = np.zeros(n_cols)  # the anchor's change per column
    for q in range(n_sl):
        for c in range(n_cols):
            dx[c] = 0.0
        for sweep in range(2):  # one pass sets the anchor's change wherever the slider slips, the second records
            for i in range(m):
                flag = iw_flag[i, q]
                if flag == 2:
                    for c in range(n_cols):
                        dx[c] = dxi[i, c]
                    continue
                ex = np.exp(-k_c * N[i] / e_f)  # d e_0 / dN = k_c ex (Eq. 22)
                k = initial_stiffness(N[i], e_f, k_c) / n_sl
                lim = mu * N[i] * iw_w[q]
                for c in range(n_cols):
                    dk = k_c * ex * dN[i, c] / n_sl
                    if flag == 0:
                        df = dk * (xi[i] - iw_x[i, q]) + k * (dxi[i, c] - dx[c])
                    else:
                        dlim = mu * iw_w[q] * dN[i, c]
                        df = flag * dlim
                        dx[c] = dxi[i, c] - flag * (dlim * k - lim * dk) / (k * k)
                    if sweep == 1:
                        out[i, c] += df


@njit(cache=True)
def friction_tangents(
    xi: np.ndarray,
    N_from: np.ndarray,
    N: np.ndarray,
    S_val: np.ndarray,
    fr: np.ndarray,
    n_min: float,
    coef: np.ndarray,
) -> None:
    """Write the partial derivatives of the integrator's friction step along the converged periodic path into ``coef``.

    S_i = step(S_{i-1}, xi_{i-1}, xi_i, N_from_i, N_i); coef[i] = d S_i / d(S_{i-1}, xi_{i-1}, xi_i, N_from_i, N_i) by
    central differences (the step's clamps included).

    Parameters
    ----------
    xi
        The tangential displacement xi along the path [m], shape (M,).
    N_from
        The normal force at each step's start [N], shape (M,).
    N
        The normal force at each step's end [N], shape (M,).
    S_val
        The Valanis state along the converged path (``periodic_friction``) [N], shape (M,).
    fr
        The friction law's record (``rig.nonlinear.friction_record``) [N/m, 1/m, N/m, -, -, -], shape (6,).
    n_min
        The normal force at or below which the contact is open [N].
    coef
        Output: each step's partial derivatives [-, N/m, N/m, -, -], shape (M, 5).
    """
    e_f, k_c, e_t, kappa, mu, slip_limit = fr[0], fr[1], fr[2], fr[3], fr[4], fr[5] > 0.5
    m = xi.size
    for i in range(m):
        j = i - 1 if i > 0 else m - 1
        x = (S_val[j], xi[j], xi[i], N_from[i], N[i])
        scale = (
            max(abs(S_val[j]), 1e-3),
            max(abs(xi[j]), abs(xi[i]), 1e-12),
            max(abs(xi[j]), abs(xi[i]), 1e-12),
            max(abs(N_from[i]), 1.0),
            max(abs(N[i]), 1.0),
        )
        for k in range(5):
            h = 1e-7 * scale[k]
            xp = [x[0], x[1], x[2], x[3], x[4]]
            xm = [x[0], x[1], x[2], x[3], x[4]]
            xp[k] += h
            xm[k] -= h
            fp = valanis_step(xp[0], xp[1], xp[2], xp[3], xp[4], e_f, k_c, e_t, kappa, mu, n_min, slip_limit)
            fm = valanis_step(xm[0], xm[1], xm[2], xm[3], xm[4], e_f, k_c, e_t, kappa, mu, n_min, slip_limit)
            coef[i, k] = (fp - fm) / (2.0 * h)


@njit(cache=True)
def propagate(coef: np.ndarray, dxi: np.ndarray, dN_from: np.ndarray, dN: np.ndarray, out: np.ndarray) -> None:
    """Write the periodic solution dS (M, n_cols) of the linearised step recurrence into ``out``.

    dS_i = a_i dS_{i-1} + b_i dxi_{i-1} + c_i dxi_i + d_i dN_from_i + e_i dN_i, for every column.

    Parameters
    ----------
    coef
        Each step's partial derivatives a_i .. e_i (``friction_tangents``) [-, N/m, N/m, -, -], shape (M, 5).
    dxi
        Changes of xi, one column per perturbation [m], shape (M, n_cols).
    dN_from
        Changes of the normal force at each step's start [N], shape (M, n_cols).
    dN
        Changes of the normal force at each step's end [N], shape (M, n_cols).
    out
        Output: the changes dS of the friction force [N], shape (M, n_cols).
    """
    m, n_cols = dxi.shape
    prod = 1.0
    for i in range(m):
        prod *= coef[i, 0]
    closure = 1.0 / (1.0 - prod) if abs(1.0 - prod) > 1e-9 else 0.0
    s = np.zeros(n_cols)  # one pass from zero gives the response r; the periodic start is r_end / (1 - prod a)
    for sweep in range(2):
        if sweep == 1:
            for c in range(n_cols):
                s[c] *= closure
        for i in range(m):
            j = i - 1 if i > 0 else m - 1
            a, b, cc, d, e = coef[i, 0], coef[i, 1], coef[i, 2], coef[i, 3], coef[i, 4]
            for c in range(n_cols):
                s[c] = a * s[c] + b * dxi[j, c] + cc * dxi[i, c] + d * dN_from[i, c] + e * dN[i, c]
                if sweep == 1:
                    out[i, c] = s[c]


@njit(cache=True)
def normal_path(
    eta: np.ndarray,
    deta: np.ndarray,
    n0: float,
    delta0: float,
    p: float,
    cubic: float,
    hc: float,
    unilateral: bool,
    N: np.ndarray,
    dN_deta: np.ndarray,
    dN_ddeta: np.ndarray,
) -> None:
    """Write the normal force and its tangents along the path (the integrator's ``normal_force``) into the outputs.

    Where a unilateral contact is open (eta >= delta0 or N <= 0) both tangents are zero.

    Parameters
    ----------
    eta
        Normal approach eta along the path [m], shape (M,).
    deta
        Its rate d eta/dt [m/s], shape (M,).
    n0
        Static normal preload N0 [N].
    delta0
        Static approach delta0 of the normal law [m].
    p
        Exponent of the unilateral power law [-].
    cubic
        Cubic hardening k_3 [N/m^3].
    hc
        Hunt-Crossley damping alpha of N (1 - alpha deta/dt) [s/m].
    unilateral
        Whether the contact may open (the power law); False: the bilateral linear spring of Eq. 13 plus the cubic.
    N
        Output: the normal force [N], shape (M,).
    dN_deta
        Output: dN/d eta [N/m], shape (M,).
    dN_ddeta
        Output: dN/d(d eta/dt) [N s/m], shape (M,).
    """
    for i in range(eta.size):
        N[i] = normal_force(eta[i], deta[i], n0, delta0, p, hc, unilateral, cubic)
        if unilateral and (eta[i] >= delta0 or N[i] <= 0.0):
            dN_deta[i] = 0.0
            dN_ddeta[i] = 0.0
            continue
        power = n0 * ((delta0 - eta[i]) / delta0) ** p if unilateral else n0 * (delta0 - eta[i]) / delta0
        nel = power - cubic * eta[i] ** 3
        dnel = (-p * power / (delta0 - eta[i]) if unilateral else -n0 / delta0) - 3.0 * cubic * eta[i] ** 2
        dN_deta[i] = dnel * (1.0 - hc * deta[i])
        dN_ddeta[i] = -hc * nel
