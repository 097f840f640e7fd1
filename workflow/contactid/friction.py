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
from numba import njit


@njit
def valanis_slope(S, xi, direction, normal_force, e_f, k_c, e_t, kappa, mu):
    """dS/dxi (N/m) of Eq. 21 at friction force S (N), displacement xi (m), motion
    direction +-1 and total normal force N (N)."""
    e0 = e_f * (1.0 - np.exp(-k_c * normal_force / e_f))  # Eq. 22
    alpha0 = mu * normal_force
    ratio = 1.0 / (alpha0 * (1.0 - kappa * e_t / e0))  # lambda / e_0
    d = ratio * direction * (e_t * xi - S)
    return e0 * (1.0 + d) / (1.0 + kappa * d)


@njit
def _clamp_to_slip_limit(S, xi, normal_force, e_f, k_c, e_t, kappa, mu):
    e0 = e_f * (1.0 - np.exp(-k_c * normal_force / e_f))
    lim = mu * normal_force * (1.0 - kappa * e_t / e0)
    base = e_t * xi
    return min(max(S, base - lim), base + lim)


@njit
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
