"""Modal parameter estimation from FRFs: least-squares complex frequency-domain
(LSCF) common-denominator fit for the poles, least-squares frequency-domain
(LSFD) fit for the residues, and selection of the physical modes.

References: Guillaume et al., "A poly-reference implementation of the
least-squares complex frequency-domain estimator", IMAC 2003; Peeters et al.,
"The PolyMAX frequency-domain method", Shock Vib. 11 (2004).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ModalEstimate:
    """Identified modes, sorted by frequency.

    natural_frequency_hz: undamped |s_r| / 2 pi (Hz); damping_ratio: -Re s_r / |s_r|;
    residues: (n_out, n_modes) complex accelerance residues (m/s^2/N * rad/s);
    peak_strength: |R| w / zeta of each mode summed over outputs (selection score);
    order: LSCF polynomial order used.
    """

    natural_frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    residues: np.ndarray
    peak_strength: np.ndarray
    order: int


def lscf_poles(frequency_hz: np.ndarray, frf: np.ndarray, order: int, weights: np.ndarray | None = None) -> np.ndarray:
    """Poles s_r (rad/s) of a common-denominator rational fit of order ``order``.

    frequency_hz: (n_f,) within the analysis band; frf: (n_out, n_f) complex.
    Only poles with positive imaginary part are returned (stable or not).
    """
    f = np.asarray(frequency_hz, dtype=float)
    H = np.atleast_2d(frf)
    dt = 1.0 / (2.0 * f.max())
    omega = 2 * np.pi * f
    X = np.exp(1j * np.outer(omega * dt, np.arange(order + 1)))  # z^j, z = exp(i w dt)
    W = np.ones_like(H.real) if weights is None else np.atleast_2d(weights)
    M = np.zeros((order + 1, order + 1))
    for o in range(H.shape[0]):
        Xo = W[o][:, None] * X
        Yo = -(W[o] * H[o])[:, None] * X
        R = (Xo.conj().T @ Xo).real
        S = (Xo.conj().T @ Yo).real
        T = (Yo.conj().T @ Yo).real
        M += T - S.T @ np.linalg.solve(R, S)
    alpha = np.ones(order + 1)
    alpha[:order] = np.linalg.lstsq(M[:order, :order], -M[:order, order], rcond=None)[0]
    z = np.roots(alpha[::-1])
    s = np.log(z.astype(complex)) / dt
    return s[s.imag > 0]


def lsfd_residues(frequency_hz: np.ndarray, frf: np.ndarray, poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Accelerance residues R_or for fixed poles, with lower (constant) and
    upper (omega^2) residual terms:
        H_o(w) = sum_r (iw)^2 [R_or / (iw - s_r) + conj(R_or) / (iw - conj(s_r))] + LR_o + UR_o w^2.
    Returns (residues (n_out, n_poles), fitted FRF (n_out, n_f)).
    """
    w = 2 * np.pi * np.asarray(frequency_hz, dtype=float)
    iw = 1j * w
    cols = []
    for s in poles:
        a = iw**2 / (iw - s)
        b = iw**2 / (iw - np.conj(s))
        cols += [a + b, 1j * (a - b)]  # Re R and Im R
    cols += [np.ones_like(w), w**2]
    A = np.array(cols).T
    Areal = np.vstack([A.real, A.imag])
    H = np.atleast_2d(frf)
    res = np.empty((H.shape[0], len(poles)), dtype=complex)
    fit = np.empty_like(H)
    for o in range(H.shape[0]):
        b = np.concatenate([H[o].real, H[o].imag])
        c = np.linalg.lstsq(Areal, b, rcond=None)[0]
        res[o] = c[0 : 2 * len(poles) : 2] + 1j * c[1 : 2 * len(poles) : 2]
        fit[o] = A @ c
    return res, fit


def fit_modes(
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    n_modes: int,
    band_hz: tuple[float, float],
    order: int = 24,
    max_damping: float = 0.2,
    weights: np.ndarray | None = None,
) -> ModalEstimate:
    """Identify the ``n_modes`` dominant physical modes in ``band_hz``.

    Poles from LSCF at ``order`` are kept if stable, inside the band and with
    0 < zeta < ``max_damping``; residues come from LSFD with all kept poles;
    the ``n_modes`` with the largest peak strength sum_o |R_or| w_r / zeta_r are
    returned, sorted by frequency. Raises ValueError when fewer are found.
    """
    f = np.asarray(frequency_hz)
    sel = (f >= band_hz[0]) & (f <= band_hz[1])
    if sel.sum() < 2 * order:
        raise ValueError(
            f"only {int(sel.sum())} frequency lines in the band {band_hz} Hz for an LSCF order of {order}; "
            "use a longer FRF segment or a wider band"
        )
    fb, Hb = f[sel], np.atleast_2d(frf)[:, sel]
    Wb = None if weights is None else np.atleast_2d(weights)[:, sel]
    s = lscf_poles(fb, Hb, order, Wb)
    wn = np.abs(s)
    zeta = -s.real / wn
    keep = (zeta > 0) & (zeta < max_damping) & (wn / (2 * np.pi) >= band_hz[0]) & (wn / (2 * np.pi) <= band_hz[1])
    s = s[keep]
    if len(s) < n_modes:
        raise ValueError(f"found {len(s)} physical poles in {band_hz} Hz, {n_modes} requested")
    R, _ = lsfd_residues(fb, Hb, s)
    wn, zeta = np.abs(s), -s.real / np.abs(s)
    strength = np.abs(R).sum(axis=0) * wn / zeta
    top = np.sort(np.argsort(strength)[::-1][:n_modes])
    top = top[np.argsort(wn[top])]
    return ModalEstimate(wn[top] / (2 * np.pi), zeta[top], R[:, top], strength[top], order)
