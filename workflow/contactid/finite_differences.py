"""Finite-difference Jacobians with absolute steps, for ``scipy.optimize.least_squares(jac=...)``.

scipy's ``diff_step`` is relative to the variable: its step is ``diff_step * |x|``. Where a variable sits at or
near zero (the log of a factor at its nominal value 1, a point at the low end of a unit range) the step shrinks
to 1e-11 or less, below the rounding of the residuals (an eigensolver's frequencies, a time-marched response),
and the Jacobian's columns become noise: the model updating's posterior sd of the lever arm came out anywhere
between 0.0002 and 0.1 for data that do not bind it at all (docs/measurements.md, "The updating's Jacobian").
These builders take the step in the variable's own units, the same at every x.
"""

from __future__ import annotations

from typing import Callable

import numpy as np


def central_difference_jacobian(
    fun: Callable[[np.ndarray], np.ndarray],
    step: float,
    lower: float | np.ndarray = -np.inf,
    upper: float | np.ndarray = np.inf,
) -> Callable[[np.ndarray], np.ndarray]:
    """Build a Jacobian of central differences of ``fun`` with an absolute step.

    The differences are one-sided (second order, three points) where x +- step would leave [``lower``, ``upper``].
    2n calls of ``fun`` per Jacobian.

    Parameters
    ----------
    fun
        Residual function R^n -> R^m: the variables x [unit of x], shape (n,), to the residuals r [unit of r],
        shape (m,).
    step
        Absolute step of every variable [unit of x] (the same at every x).
    lower
        Lower bounds of the variables [unit of x]: a float for all, or shape (n,).
    upper
        Upper bounds of the variables [unit of x]: a float for all, or shape (n,).

    Returns
    -------
    jac : Callable[[np.ndarray], np.ndarray]
        jac(x), x [unit of x] of shape (n,), returns the Jacobian dr/dx [unit of r / unit of x], shape (m, n).
    """

    def jac(x) -> np.ndarray:
        x = np.asarray(x, float)
        lo = np.broadcast_to(np.asarray(lower, float), x.shape)
        hi = np.broadcast_to(np.asarray(upper, float), x.shape)
        cols = []
        for i in range(x.size):
            e = np.zeros_like(x)
            e[i] = step
            if x[i] - step >= lo[i] and x[i] + step <= hi[i]:
                cols.append((np.asarray(fun(x + e)) - np.asarray(fun(x - e))) / (2.0 * step))
                continue
            s = 1.0 if x[i] + 2.0 * step <= hi[i] else -1.0  # away from the bound that is too near
            f0, f1, f2 = (np.asarray(fun(x + k * s * e), float) for k in (0.0, 1.0, 2.0))
            cols.append(s * (-3.0 * f0 + 4.0 * f1 - f2) / (2.0 * step))
        return np.column_stack(cols)

    return jac


def forward_difference_jacobian(
    fun: Callable[[np.ndarray], np.ndarray],
    step: float,
    lower: float | np.ndarray = -np.inf,
    upper: float | np.ndarray = np.inf,
) -> tuple[Callable, Callable]:
    """Build ``fun`` that remembers its last evaluation and a Jacobian of forward differences that reuses it.

    The Jacobian takes forward differences of the absolute ``step`` (backward where x + step would pass ``upper``)
    and reuses fun'(x) when least_squares has just evaluated it: n calls of ``fun`` per Jacobian, for residuals that
    cost a simulation each.

    Parameters
    ----------
    fun
        Residual function R^n -> R^m: the variables x [unit of x], shape (n,), to the residuals r [unit of r],
        shape (m,).
    step
        Absolute step of every variable [unit of x] (the same at every x).
    lower
        Lower bounds of the variables [unit of x]: a float for all, or shape (n,).
    upper
        Upper bounds of the variables [unit of x]: a float for all, or shape (n,).

    Returns
    -------
    remembered : Callable
        fun'(x): ``fun`` that keeps its last x and residuals r [unit of r], shape (m,), and returns the residuals as
        floats.
    jac : Callable
        jac(x), x [unit of x] of shape (n,), returns the Jacobian dr/dx [unit of r / unit of x], shape (m, n).
    """
    last: dict = {}

    def remembered(x) -> np.ndarray:
        x = np.array(x, float)
        last["x"], last["f"] = x, np.asarray(fun(x), float)
        return last["f"]

    def jac(x) -> np.ndarray:
        x = np.asarray(x, float)
        f0 = last["f"] if "x" in last and np.array_equal(last["x"], x) else np.asarray(fun(x), float)
        hi = np.broadcast_to(np.asarray(upper, float), x.shape)
        lo = np.broadcast_to(np.asarray(lower, float), x.shape)
        cols = []
        for i in range(x.size):
            h = step if x[i] + step <= hi[i] or x[i] - step < lo[i] else -step
            e = np.zeros_like(x)
            e[i] = h
            cols.append((np.asarray(fun(x + e), float) - f0) / h)
        return np.column_stack(cols)

    return remembered, jac
