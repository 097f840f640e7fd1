"""The FRFs the identified modes synthesise: the modal fit's poles (results/linear/modal.nc) with LSFD residues and
residual terms fitted to the measured FRFs (results/linear/frf.nc) in modal.band_hz, evaluated on every line of
the measured frequency axis (outside the band the residual terms extrapolate).

    H_o(w) = sum_r (iw)^2 [R_or / (iw - s_r) + conj(R_or) / (iw - conj(s_r))] + LR_o + UR_o w^2 + i UI_o w^3   (m/s^2/N)

as ``modal_fit.lsfd_fit`` fits it, with the identified modes' poles only.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .linear_chain import complex_frf
from .modal_fit import lsfd_fit, mode_poles, residual_terms


def identified_poles(modal: xr.Dataset) -> np.ndarray:
    """Poles s_r (rad/s) of the identified modes in modal.nc (``modal_fit.mode_poles``)."""
    return mode_poles(modal["natural_frequency"].values, modal["damping_ratio"].values)


def modal_terms(frequency_hz: np.ndarray, poles: np.ndarray, residues: np.ndarray) -> np.ndarray:
    """(n_out, n_f) the modes' part of the accelerance (m/s^2/N): sum_r (iw)^2 [R/(iw - s) + conj(R)/(iw - conj s)];
    residues (n_out, n_modes) in m/s^2/N rad/s."""
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
    """(n_out, n_f) complex accelerance (m/s^2/N) synthesised from modes of ``natural_frequency_hz`` (Hz) and
    ``damping_ratio`` on every line of ``frequency_hz``: their residues and the lower and upper residuals
    (LR + UR w^2 + i UI w^3, LR, UR, UI real) fitted by least squares to ``frf`` (n_out, n_f; m/s^2/N) inside
    ``band_hz``, as modal_fit.lsfd_fit fits them (outside the band the residual terms extrapolate)."""
    f = np.asarray(frequency_hz, dtype=float)
    h = np.atleast_2d(frf)
    band = (f >= band_hz[0]) & (f <= band_hz[1])
    poles = mode_poles(natural_frequency_hz, damping_ratio)
    residues, coef, _ = lsfd_fit(f[band], h[:, band], poles)
    return modal_terms(f, poles, residues) + coef @ residual_terms(f)


def synthesised_frf(frf: xr.Dataset, modal: xr.Dataset) -> np.ndarray:
    """(sensor, frequency) complex accelerance (m/s^2/N) synthesised from the identified modes (modal.nc) on the
    lines of ``frf`` (frf.nc), fitted in the modal fit's band (modal.attrs band_low_hz, band_high_hz)."""
    band = (float(modal.attrs["band_low_hz"]), float(modal.attrs["band_high_hz"]))
    return synthesised_accelerance(
        frf["frequency"].values,
        complex_frf(frf),
        modal["natural_frequency"].values,
        modal["damping_ratio"].values,
        band,
    )
