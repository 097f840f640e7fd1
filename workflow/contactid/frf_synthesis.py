"""The FRFs the identified modes synthesise, on every line of the measured frequency axis.

The modal fit's poles (results/linear/modal.nc) with LSFD residues and residual terms fitted to the measured FRFs
(results/linear/frf.nc) in modal.band_hz, evaluated on every line of the measured frequency axis (outside the band
the residual terms extrapolate).

    H_o(w) = sum_r (iw)^2 [R_or / (iw - s_r) + conj(R_or) / (iw - conj(s_r))] + LR_o + UR_o w^2 + i UI_o w^3   (m/s^2/N)

as ``modal_fit.lsfd_fit`` fits it, with the identified modes' poles only.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .linear_chain import complex_frf
from .modal_fit import lsfd_fit, mode_poles, residual_terms


def identified_poles(modal: xr.Dataset) -> np.ndarray:
    """Return the poles s_r of the identified modes in modal.nc (``modal_fit.mode_poles``).

    Parameters
    ----------
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] along ``mode``.

    Returns
    -------
    poles : np.ndarray
        Complex poles s_r = -zeta w_n + i w_n sqrt(1 - zeta^2) [rad/s], shape (n_modes,), one per identified mode.
    """
    return mode_poles(modal["natural_frequency"].values, modal["damping_ratio"].values)


def modal_terms(frequency_hz: np.ndarray, poles: np.ndarray, residues: np.ndarray) -> np.ndarray:
    """Return the modes' part of the accelerance: sum_r (iw)^2 [R/(iw - s) + conj(R)/(iw - conj s)].

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    poles
        Complex poles s_r [rad/s], shape (n_modes,).
    residues
        Complex residues R_or [m/(N s)], shape (n_out, n_modes): the accelerance's residues divided by (i w)^2, i.e.
        the receptance's (m/N times rad/s), as ``modal_fit.lsfd_fit`` fits them.

    Returns
    -------
    accelerance : np.ndarray
        The modes' complex accelerance [m/s^2/N], shape (n_out, n_f).
    """
    iw = 2j * np.pi * np.asarray(frequency_hz, dtype=float)
    a = iw[None, :] ** 2 / (iw[None, :] - poles[:, None])
    b = iw[None, :] ** 2 / (iw[None, :] - np.conj(poles)[:, None])
    return residues @ a + np.conj(residues) @ b


def synthesised_accelerance(
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    natural_frequency_hz: np.ndarray,
    damping_ratio: np.ndarray,
    band_hz: tuple[float, float],
) -> np.ndarray:
    """Return the accelerance synthesised from given modes on every line of ``frequency_hz``.

    The modes' residues and the lower and upper residuals (LR + UR w^2 + i UI w^3, LR, UR, UI real) are fitted by
    least squares to ``frf`` inside ``band_hz``, as modal_fit.lsfd_fit fits them; outside the band the residual terms
    extrapolate.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The measured complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    natural_frequency_hz
        The modes' undamped natural frequencies [Hz], shape (n_modes,).
    damping_ratio
        The modes' damping ratios [-], shape (n_modes,).
    band_hz
        The fitting band (low, high) [Hz].

    Returns
    -------
    accelerance : np.ndarray
        The synthesised complex accelerance [m/s^2/N], shape (n_out, n_f).
    """
    f = np.asarray(frequency_hz, dtype=float)
    h = np.atleast_2d(frf)
    band = (f >= band_hz[0]) & (f <= band_hz[1])
    poles = mode_poles(natural_frequency_hz, damping_ratio)
    residues, coef, _ = lsfd_fit(f[band], h[:, band], poles)
    return modal_terms(f, poles, residues) + coef @ residual_terms(f)


def synthesised_frf(frf: xr.Dataset, modal: xr.Dataset) -> np.ndarray:
    """Return the accelerance the identified modes (modal.nc) synthesise on the lines of ``frf`` (frf.nc).

    The residues and residual terms are fitted in the modal fit's band (modal.attrs band_low_hz, band_high_hz).

    Parameters
    ----------
    frf
        The random test's FRFs (frf.nc): the ``frequency`` coordinate [Hz] and ``h1_real``, ``h1_imag`` [m/s^2/N]
        along (sensor, frequency).
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] along ``mode``,
        attributes ``band_low_hz`` and ``band_high_hz`` [Hz].

    Returns
    -------
    accelerance : np.ndarray
        The synthesised complex accelerance [m/s^2/N], shape (n_sensors, n_f).
    """
    band = (float(modal.attrs["band_low_hz"]), float(modal.attrs["band_high_hz"]))
    return synthesised_accelerance(
        frf["frequency"].values,
        complex_frf(frf),
        modal["natural_frequency"].values,
        modal["damping_ratio"].values,
        band,
    )
