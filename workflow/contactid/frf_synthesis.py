"""The FRFs the identified modes synthesise: the modal fit's poles (results/linear/modal.nc) with LSFD residues and
residual terms fitted to the measured FRFs (results/linear/frf.nc) in modal.band_hz, evaluated on every line of
the measured frequency axis (outside the band the residual terms extrapolate).

    H_o(w) = sum_r (iw)^2 [R_or / (iw - s_r) + conj(R_or) / (iw - conj(s_r))] + LR_o + UR_o w^2   (m/s^2/N)

as ``modal_fit.lsfd_residues`` fits it, with the identified modes' poles only.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .linear_chain import complex_frf
from .modal_fit import lsfd_residues


def identified_poles(modal: xr.Dataset) -> np.ndarray:
    """Poles s_r = -zeta_r w_r + i w_r sqrt(1 - zeta_r^2) (rad/s) of the identified modes (w_r = 2 pi f_r, the
    undamped natural frequency |s_r|)."""
    w = 2 * np.pi * modal["natural_frequency"].values
    z = modal["damping_ratio"].values
    return -z * w + 1j * w * np.sqrt(1.0 - z**2)


def modal_terms(frequency_hz: np.ndarray, poles: np.ndarray, residues: np.ndarray) -> np.ndarray:
    """(n_out, n_f) the modes' part of the accelerance (m/s^2/N): sum_r (iw)^2 [R/(iw - s) + conj(R)/(iw - conj s)];
    residues (n_out, n_modes) in m/s^2/N rad/s."""
    iw = 2j * np.pi * np.asarray(frequency_hz, dtype=float)
    a = iw[None, :] ** 2 / (iw[None, :] - poles[:, None])
    b = iw[None, :] ** 2 / (iw[None, :] - np.conj(poles)[:, None])
    return residues @ a + np.conj(residues) @ b


def synthesised_frf(frf: xr.Dataset, modal: xr.Dataset) -> np.ndarray:
    """(sensor, frequency) complex accelerance (m/s^2/N) synthesised from the identified modes on the lines of
    ``frf``: residues and the real lower and upper residuals (LR + UR w^2) fitted by least squares to the measured
    H1 in the modal fit's band (modal.attrs band_low_hz, band_high_hz), as modal_fit.lsfd_residues fits them."""
    f = frf["frequency"].values
    h = complex_frf(frf)
    band = (f >= float(modal.attrs["band_low_hz"])) & (f <= float(modal.attrs["band_high_hz"]))
    poles = identified_poles(modal)
    residues, _ = lsfd_residues(f[band], h[:, band], poles)
    modes = modal_terms(f, poles, residues)
    w2 = (2 * np.pi * f) ** 2
    basis = np.array([np.ones(band.sum()), w2[band]]).T  # real LR, UR: fitted to the real and imaginary parts
    rest = h[:, band] - modes[:, band]
    A = np.vstack([basis, np.zeros_like(basis)])
    residual = np.array([np.linalg.lstsq(A, np.concatenate([r.real, r.imag]), rcond=None)[0] for r in rest])
    return modes + residual[:, :1] + residual[:, 1:] * w2[None, :]
