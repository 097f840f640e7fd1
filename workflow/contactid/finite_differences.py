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
    fun: Callable[[np.ndarray], np.ndarray], step: float, lower=-np.inf, upper=np.inf
) -> Callable[[np.ndarray], np.ndarray]:
    """jac(x) -> (m, n): central differences of ``fun`` (R^n -> R^m) with the absolute ``step`` (same units as
    x); one-sided (second order, three points) where x +- step would leave [``lower``, ``upper``]. 2n calls of
    ``fun`` per Jacobian."""

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
    fun: Callable[[np.ndarray], np.ndarray], step: float, lower=-np.inf, upper=np.inf
) -> tuple[Callable, Callable]:
    """(fun', jac): ``fun`` that remembers its last evaluation, and jac(x) -> (m, n) by forward differences of the
    absolute ``step`` (backward where x + step would pass ``upper``) that reuses fun'(x) when least_squares has just
    evaluated it. n calls of ``fun`` per Jacobian, for residuals that cost a simulation each."""
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
