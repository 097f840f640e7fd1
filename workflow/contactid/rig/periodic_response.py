"""What a harmonic-balance solve returns and what its grid costs: the periodic response and its memory bound.

``rig.harmonic_balance.HarmonicBalance.solve`` returns a ``PeriodicResponse``; ``grid_bytes`` bounds the memory a
``HarmonicBalance`` takes while it solves, so that a caller (``gap.simulation``) can check the work against
``rig.nonlinear.WORK_LIMIT_BYTES`` before it builds one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PeriodicResponse:
    """A periodic steady state found by harmonic balance.

    Attributes
    ----------
    Z
        Complex harmonics of the mass-normalised coordinates z [kg^0.5 m], shape (n_r, H + 1): column 0 the mean
        (real), column h the amplitude Z_h of Im(Z_h e^{i h w t}).
    A
        Complex harmonics of the acceleration, as the integrator computes it (the second difference) [kg^0.5 m/s^2],
        shape (n_r, H + 1).
    w
        Excitation angular frequency [rad/s].
    grid
        The period's signals on its M steps from t = 0: ``t`` [s], ``z`` [kg^0.5 m], ``v`` [kg^0.5 m/s] and ``a``
        [kg^0.5 m/s^2] (M, n_r); ``xi``, ``eta`` [m], ``dxi``, ``deta`` [m/s], ``N``, ``S`` and the friction law's
        own state ``S_valanis`` [N] (M,).
    converged
        Whether Newton converged.
    iterations
        Newton's iterations.
    residual
        The final residual relative to the force's norm (both in the real basis) [-].
    iwan_anchors
        The Iwan sliders' anchors at t = 0 [m], shape (n_sliders,).
    """

    Z: np.ndarray
    A: np.ndarray
    w: float
    grid: dict
    converged: bool
    iterations: int
    residual: float
    iwan_anchors: np.ndarray


def grid_bytes(M: int, H: int, n: int) -> int:
    """Return the peak memory of a ``HarmonicBalance`` while it solves.

    Its bases E, Ec, Eb, the path's signals and the friction law's tangents, all (M, ...): measured 5.0 kB per point at
    H = 18, n = 11 and 2.8 kB at H = 9 (M = 80000 and 160000; the fixed part is small), 8 (17 (2H + 1) + 8 n) bytes per
    point bound both.

    Parameters
    ----------
    M
        Points (integrator steps) per period.
    H
        Number of harmonics.
    n
        Number of coordinates of the reduced model.

    Returns
    -------
    int
        The memory bound, in bytes.
    """
    return int(M) * 8 * (17 * (2 * int(H) + 1) + 8 * int(n))
