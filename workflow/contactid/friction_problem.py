"""The friction fit's least-squares problem: the law's residuals against an identified S, and their polish.

The identified xi, N and S on a grid of one period (``FitProblem``), the parameters searched in the unit cube (e_f and
k_c on a log scale), and the local least-squares polish from a start (``least_squares_polish``): the friction fit
(``contactid.friction_fit``) runs it after its GA and on each refined grid, the gap diagnosis' refits
(``contactid.gap.refit``) run it alone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numba
import numpy as np

from .friction import valanis_friction_force

if TYPE_CHECKING:
    from scipy.optimize import OptimizeResult

LOG_SCALED = (True, True, False, False, False)  # e_f, k_c on a log scale

N_OPEN = 1.0e-3  # N: where the identified normal force is lower, the contact is taken as open (S = 0)


class FitProblem:
    """Least-squares problem of the friction fit.

    The identified xi, N and S on a grid of one period, the parameters' bounds and the regularization. The parameters
    are searched in the unit cube: e_f and k_c on a log scale (``LOG_SCALED``), the others linearly. Where the
    identified N falls below ``N_OPEN`` the contact opens and carries no friction: the law is evaluated there with a
    vanishing normal force (the kernel refuses N <= 0). The identified S is taken with its mean removed, and the
    residuals are relative to its rms (``scale``).

    Parameters
    ----------
    xi
        Tangential contact motion over one period [m], shape (n_samples,).
    normal_force
        Total normal force N, preload included, compression positive [N], shape (n_samples,).
    S
        Identified friction force over the same period [N], shape (n_samples,).
    bounds
        Search bounds, five (low, high) pairs in the order e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -].
    regularization
        How Eq. 21 is read: ``none`` or ``slip_limit`` (see ``contactid.friction``).
    """

    def __init__(
        self,
        xi: np.ndarray,
        normal_force: np.ndarray,
        S: np.ndarray,
        bounds: Sequence[tuple[float, float]],
        regularization: str = "none",
    ):
        # where the identified N falls to zero the contact opens and carries no friction: the law is
        # evaluated there with a vanishing normal force (the kernel refuses N <= 0)
        self.xi, self.N = xi, np.maximum(normal_force, N_OPEN)
        self.regularization = regularization
        self.S = S - S.mean()
        self.scale = np.sqrt(np.mean(self.S**2))
        self.lo = np.array([np.log10(b[0]) if lg else b[0] for b, lg in zip(bounds, LOG_SCALED)])
        self.hi = np.array([np.log10(b[1]) if lg else b[1] for b, lg in zip(bounds, LOG_SCALED)])

    def physical(self, u: np.ndarray) -> np.ndarray:
        """Return the parameters at unit-cube coordinates.

        Parameters
        ----------
        u
            Unit-cube coordinates [-], shape (n, 5) or (5,) for one set.

        Returns
        -------
        params : np.ndarray
            Parameter sets e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -] by column, shape (n, 5).
        """
        v = self.lo + np.atleast_2d(u) * (self.hi - self.lo)
        out = v.copy()
        log_cols = np.array(LOG_SCALED)
        out[:, log_cols] = 10.0 ** v[:, log_cols]
        return out

    def unit(self, p: np.ndarray) -> np.ndarray:
        """Return the unit-cube coordinates of parameter sets; the inverse of :meth:`physical`.

        Parameters
        ----------
        p
            Parameter sets e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -] by column, shape (n, 5) or (5,) for one set.

        Returns
        -------
        u : np.ndarray
            Unit-cube coordinates [-], shape (n, 5).
        """
        v = np.where(LOG_SCALED, np.log10(np.maximum(np.atleast_2d(p), 1e-300)), np.atleast_2d(p))
        return (v - self.lo) / (self.hi - self.lo)

    def residuals(self, params: np.ndarray) -> np.ndarray:
        """Return the residuals of the mean-removed S for each parameter set, over the rms of the identified S.

        Parameters
        ----------
        params
            Parameter sets e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -] by column, shape (n, 5).

        Returns
        -------
        residuals : np.ndarray
            Residuals of each set's S against the identified S [-], shape (n, n_samples).
        """
        S = valanis_friction_force(self.xi, self.N, params, regularization=self.regularization)
        S = S - S.mean(axis=1, keepdims=True)
        return (S - self.S) / self.scale

    def misfit(self, params: np.ndarray) -> np.ndarray:
        """Return the NRMSE of the mean-removed S for each parameter set.

        Parameters
        ----------
        params
            Parameter sets e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -] by column, shape (n, 5).

        Returns
        -------
        misfit : np.ndarray
            The rms of each set's residuals (``residuals``) [-], shape (n,).
        """
        return np.sqrt(np.mean(self.residuals(params) ** 2, axis=1))


def least_squares_polish(
    problem: FitProblem, u0: np.ndarray, fixed: dict | None = None, xtol: float = 1e-10, ftol: float = 1e-12
) -> tuple[np.ndarray, float, OptimizeResult]:
    """Polish a parameter set by least squares in the unit cube.

    The Jacobian is taken by forward differences of step 1e-4 in the unit cube (backward at the upper bound), every
    perturbed set in one call of the law's kernel, on one numba thread (a handful of sets per call: parallel threads
    cost more than they give).

    Parameters
    ----------
    problem
        The fit's problem (identified signals, bounds, regularization).
    u0
        Start in unit-cube coordinates [-], shape (5,).
    fixed
        {parameter index: unit-cube value} of the parameters held fixed; None: all free.
    xtol
        scipy's ``least_squares`` tolerance on the change of the parameters [-] (the chain's fit and its intervals keep
        the tight default).
    ftol
        scipy's ``least_squares`` tolerance on the change of the cost [-] (the tight default, as ``xtol``).

    Returns
    -------
    u : np.ndarray
        The optimum in unit-cube coordinates [-], shape (5,), the fixed entries at their values.
    ssr : float
        Sum of the squared residuals at the optimum (relative to the rms of the identified S) [-].
    result : OptimizeResult
        scipy's least-squares result (its ``jac`` over the free parameters).
    """
    fixed = fixed or {}
    free = [i for i in range(5) if i not in fixed]

    def full(x):
        u = np.empty(5)
        u[free] = x
        for i, v in fixed.items():
            u[i] = v
        return u

    last = {}

    def fun(x):
        last["x"], last["r"] = x.copy(), problem.residuals(problem.physical(full(x)))[0]
        return last["r"]

    def jac(x):
        # forward differences of step 1e-4 (backward at the upper bound), every perturbed set in one call of
        # the law's kernel, which evaluates parameter sets in parallel
        r0 = last["r"] if "x" in last and np.array_equal(last["x"], x) else fun(x)
        h = np.where(x + 1e-4 <= 1.0, 1e-4, -1e-4)
        X = x + np.diag(h)
        R = problem.residuals(problem.physical(np.array([full(row) for row in X])))
        return ((R - r0) / h[:, None]).T

    from scipy.optimize import least_squares  # here: validation and the gap's modules import this one without it

    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # a handful of sets per call: parallel threads cost more than they give
    try:
        r = least_squares(fun, np.clip(u0[free], 0, 1), jac=jac, bounds=(0.0, 1.0), x_scale=0.05, xtol=xtol, ftol=ftol)
    finally:
        numba.set_num_threads(threads)
    return full(r.x), float(np.sum(r.fun**2)), r
