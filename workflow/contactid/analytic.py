"""Closed-form natural frequencies of uniform Euler-Bernoulli beams (test references)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def _roots(fun, n: int, first_interval: int) -> np.ndarray:
    """One root per interval (k pi, (k+1) pi), k = first_interval, ..."""
    roots = []
    for k in range(first_interval, first_interval + n):
        roots.append(brentq(fun, k * np.pi + 1e-9, (k + 1) * np.pi - 1e-9, xtol=1e-15))
    return np.asarray(roots)


def clamped_free_eigenvalues(n: int) -> np.ndarray:
    """beta_i L of a clamped-free beam: cos(bL) cosh(bL) = -1 (dimensionless)."""
    return _roots(lambda x: np.cos(x) + 1.0 / np.cosh(x), n, 0)


def clamped_pinned_eigenvalues(n: int) -> np.ndarray:
    """beta_i L of a clamped-pinned beam: tan(bL) = tanh(bL) (dimensionless)."""
    return _roots(lambda x: np.sin(x) - np.cos(x) * np.tanh(x), n, 1)


def beam_frequencies_hz(
    beta_l: np.ndarray, bending_stiffness: float, mass_per_length: float, length: float
) -> np.ndarray:
    """f_i = (beta_i L)^2 / (2 pi L^2) sqrt(EI / rho A) (Hz)."""
    return np.asarray(beta_l) ** 2 / (2 * np.pi * length**2) * np.sqrt(bending_stiffness / mass_per_length)
