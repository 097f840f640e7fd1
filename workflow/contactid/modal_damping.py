"""The damping ratio of every mode of the identified model, from the ratios identified on its lowest beam modes.

The random test's modal fit identifies damping ratios on the lowest beam modes only; the inverse identification
(``identification.inverse_harmonics``) and the gap diagnosis's simulations damp every mode of the model. The
identified ratios go to the beam modes in order and the first to the block's suspension; above the identified modes
the ratios' trend with frequency is carried on (``extrapolated_damping``): a power law zeta ~ f^gamma or Rayleigh
damping, whichever the identified modes support, at most MAX_EXTRAPOLATED_ZETA.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .beam_model import FEModel
from .beam_modes import all_modes

# the extrapolated damping ratio's ceiling (an overdamped static contact shape stays overdamped; the rig's own cap)
MAX_EXTRAPOLATED_ZETA = 2.0


def damping_exponent(frequencies_hz: np.ndarray | Sequence[float], zeta: np.ndarray | Sequence[float]) -> float:
    """Return the exponent gamma of zeta ~ f^gamma fitted to identified modes, kept in [0, 1].

    Least squares on log zeta against log f: 0 where the ratios do not grow with frequency (modal damping, the
    identified model's form), 1 for stiffness-proportional damping (zeta_i = beta omega_i / 2). Needs two modes or
    more (else 0); a mode whose frequency or ratio is not positive and finite is left out.

    Parameters
    ----------
    frequencies_hz
        The identified modes' natural frequencies [Hz], shape (n_id,).
    zeta
        Their damping ratios [-], shape (n_id,).

    Returns
    -------
    gamma : float
        The exponent, within [0, 1] [-].
    """
    f, z = _positive(frequencies_hz, zeta)
    if f.size < 2 or np.ptp(np.log(f)) < 1e-6:
        return 0.0
    gamma = np.polyfit(np.log(f), np.log(z), 1)[0]
    return float(np.clip(gamma, 0.0, 1.0))


def rayleigh_coefficients(
    frequencies_hz: np.ndarray | Sequence[float], zeta: np.ndarray | Sequence[float]
) -> tuple[float, float]:
    """Return the coefficients of Rayleigh damping C = alpha M + beta K fitted to identified modes.

    zeta_i = alpha / (2 omega_i) + beta omega_i / 2, fitted by non-negative least squares on the relative misfit;
    both are 0 with fewer than two modes (a mode whose frequency or ratio is not positive and finite is left out).

    Parameters
    ----------
    frequencies_hz
        The identified modes' natural frequencies [Hz], shape (n_id,).
    zeta
        Their damping ratios [-], shape (n_id,).

    Returns
    -------
    alpha : float
        The mass-proportional coefficient, >= 0 [1/s].
    beta : float
        The stiffness-proportional coefficient, >= 0 [s].
    """
    from scipy.optimize import nnls

    f, z = _positive(frequencies_hz, zeta)
    if f.size < 2:
        return 0.0, 0.0
    w = 2 * np.pi * f
    coef, _ = nnls(np.column_stack([0.5 / w, 0.5 * w]) / z[:, None], np.ones(f.size))
    return float(coef[0]), float(coef[1])


def _positive(frequencies_hz, zeta):
    f, z = np.asarray(frequencies_hz, dtype=float), np.asarray(zeta, dtype=float)
    ok = (f > 0) & (z > 0) & np.isfinite(f) & np.isfinite(z)
    return f[ok], z[ok]


def extrapolated_damping(
    frequencies_hz: np.ndarray | Sequence[float],
    zeta: np.ndarray | Sequence[float],
    f_above: np.ndarray | Sequence[float],
) -> np.ndarray:
    """Return damping ratios at frequencies above the identified modes: the identified ratios' trend carried on.

    Never below the last identified ratio, at most MAX_EXTRAPOLATED_ZETA. The trend is the power law
    zeta_last (f / f_last)^gamma (``damping_exponent``: modal gamma = 0, stiffness-proportional 1), or Rayleigh
    damping (``rayleigh_coefficients``) where its relative rms misfit is at most half the power law's and its
    stiffness term carries half the last ratio or more: its ratios grow as beta omega / 2 once the mass term has
    faded (a structure with both terms, as many FE simulators damp theirs, shows a slope under 1 over the identified
    modes and would be damped too little above them by the power law).

    Parameters
    ----------
    frequencies_hz
        The identified modes' natural frequencies, ascending (the last is f_last) [Hz], shape (n_id,).
    zeta
        Their damping ratios [-], shape (n_id,).
    f_above
        The frequencies to give a ratio [Hz], shape (n_above,).

    Returns
    -------
    zeta_above : np.ndarray
        The damping ratios at ``f_above`` [-], shape (n_above,).
    """
    f, z = np.asarray(frequencies_hz, dtype=float), np.asarray(zeta, dtype=float)
    f_above = np.asarray(f_above, dtype=float)
    last = float(z[-1])
    gamma = damping_exponent(f, z)
    power = lambda x: last * (x / f[-1]) ** gamma  # noqa: E731
    alpha, beta = rayleigh_coefficients(f, z)
    rayleigh = lambda x: alpha / (4 * np.pi * x) + beta * np.pi * x  # noqa: E731
    misfit = lambda model: float(np.sqrt(np.mean((model(f) / z - 1.0) ** 2)))  # noqa: E731
    # Rayleigh where it fits clearly better and its stiffness term already carries half the last ratio: ratios that
    # fall over the band and then level off (mass-proportional damping with a floor) are not grown from a trace of
    # beta
    grows = beta * np.pi * f[-1] >= 0.5 * last
    best = rayleigh if grows and misfit(rayleigh) < 0.5 * misfit(power) else power
    return np.minimum(np.maximum(best(f_above), last), MAX_EXTRAPOLATED_ZETA)


def damping_by_mode(
    structural: np.ndarray,
    identified_zeta: np.ndarray | Sequence[float],
    frequencies_hz: np.ndarray | None = None,
) -> np.ndarray:
    """Return the damping ratio of every mode of a model, from the ratios identified on its beam modes.

    The identified ratios go to the structural modes in order, and the first to the other modes (the block's
    suspension). Above the identified modes (the higher beam modes and the static contact shapes, which the random
    test does not measure): the last identified ratio, grown with frequency as the identified ratios grow
    (``extrapolated_damping`` over the structural modes' ``frequencies_hz``, when given). A modally damped structure
    keeps the last ratio; a stiffness-proportionally or Rayleigh-damped one damps its static contact shapes as
    strongly as it does, which shapes the identified contact forces' phase (kappa was 17-38 % low on
    stiffness-proportional rigs of the compound benchmark, docs/identification.md).

    Parameters
    ----------
    structural
        Whether each mode is the beam's (True) or the block's suspension (False), modes in ascending frequency
        (bool [-]), shape (n_modes,).
    identified_zeta
        The damping ratios identified on the lowest structural modes, in order [-], shape (n_id,).
    frequencies_hz
        Every mode's natural frequency [Hz], shape (n_modes,); None: the modes above the identified ones keep the
        last identified ratio.

    Returns
    -------
    zeta : np.ndarray
        The damping ratio of every mode [-], shape (n_modes,).
    """
    zeta = np.full(np.size(structural), float(identified_zeta[0]))
    beam = np.flatnonzero(structural)
    n_id = len(identified_zeta)
    for k, idx in enumerate(beam):
        zeta[idx] = identified_zeta[min(k, n_id - 1)]
    if frequencies_hz is not None and beam.size > n_id >= 2:
        f = np.asarray(frequencies_hz, dtype=float)
        zeta[beam[n_id:]] = extrapolated_damping(f[beam[:n_id]], identified_zeta, f[beam[n_id:]])
    return zeta


def modal_damping_vector(model: FEModel, identified_zeta: np.ndarray) -> np.ndarray:
    """Return the damping ratio of every FE mode (``damping_by_mode``).

    A mode is structural (the beam's) where less than half of its kinetic energy lies in the block.

    Parameters
    ----------
    model
        The linear FE model; all its undamped modes (``beam_modes.all_modes``) are given a ratio.
    identified_zeta
        The damping ratios identified on the lowest structural modes, in order (the modal fit's
        ``damping_ratio``) [-], shape (n_id,).

    Returns
    -------
    zeta : np.ndarray
        The damping ratio of every FE mode, ascending frequency [-], shape (n_dof,).
    """
    modes = all_modes(model)
    return damping_by_mode(modes.block_energy_fraction < 0.5, identified_zeta, modes.frequencies_hz)
