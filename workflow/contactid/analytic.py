"""Closed-form natural frequencies of uniform Euler-Bernoulli beams (test references)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def _roots(fun, n: int, first_interval: int) -> np.ndarray:
    """Return one root of ``fun`` per interval (k pi, (k+1) pi), k = first_interval, ..., n intervals in all."""
    roots = []
    for k in range(first_interval, first_interval + n):
        roots.append(brentq(fun, k * np.pi + 1e-9, (k + 1) * np.pi - 1e-9, xtol=1e-15))
    return np.asarray(roots)


def clamped_free_eigenvalues(n: int) -> np.ndarray:
    """Return the eigenvalues beta_i L of a clamped-free beam.

    They are the roots of cos(bL) cosh(bL) = -1, one in each interval (k pi, (k+1) pi), k = 0, 1, ...

    Parameters
    ----------
    n
        How many eigenvalues, lowest first.

    Returns
    -------
    beta_l : np.ndarray
        The dimensionless eigenvalues beta_i L [-], shape (n,), ascending.
    """
    return _roots(lambda x: np.cos(x) + 1.0 / np.cosh(x), n, 0)


def clamped_pinned_eigenvalues(n: int) -> np.ndarray:
    """Return the eigenvalues beta_i L of a clamped-pinned beam.

    They are the roots of tan(bL) = tanh(bL), one in each interval (k pi, (k+1) pi), k = 1, 2, ...

    Parameters
    ----------
    n
        How many eigenvalues, lowest first.

    Returns
    -------
    beta_l : np.ndarray
        The dimensionless eigenvalues beta_i L [-], shape (n,), ascending.
    """
    return _roots(lambda x: np.sin(x) - np.cos(x) * np.tanh(x), n, 1)


def beam_frequencies_hz(
    beta_l: np.ndarray, bending_stiffness: float, mass_per_length: float, length: float
) -> np.ndarray:
    """Return the natural frequencies of a uniform Euler-Bernoulli beam from its eigenvalues.

    f_i = (beta_i L)^2 / (2 pi L^2) sqrt(EI / rho A).

    Parameters
    ----------
    beta_l
        The dimensionless eigenvalues beta_i L [-], shape (n,) (``clamped_free_eigenvalues``,
        ``clamped_pinned_eigenvalues``).
    bending_stiffness
        The bending stiffness EI [N m^2].
    mass_per_length
        The mass per unit length rho A [kg/m].
    length
        The beam's length L [m].

    Returns
    -------
    frequencies : np.ndarray
        Natural frequencies f_i [Hz], shape (n,), in the order of ``beta_l``.
    """
    return np.asarray(beta_l) ** 2 / (2 * np.pi * length**2) * np.sqrt(bending_stiffness / mass_per_length)
