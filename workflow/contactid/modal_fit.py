"""Modal parameter estimation from FRFs: LSCF poles, LSFD residues and the physical modes.

A least-squares complex frequency-domain (LSCF) common-denominator fit for the poles, a least-squares
frequency-domain (LSFD) fit for the residues, and selection of the physical modes.

References: Guillaume et al., "A poly-reference implementation of the
least-squares complex frequency-domain estimator", IMAC 2003; Peeters et al.,
"The PolyMAX frequency-domain method", Shock Vib. 11 (2004).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ModalEstimate:
    """Identified modes, sorted by frequency.

    Attributes
    ----------
    natural_frequency_hz
        Undamped natural frequencies |s_r| / 2 pi [Hz], shape (n_modes,).
    damping_ratio
        Damping ratios -Re s_r / |s_r| [-], shape (n_modes,).
    residues
        Complex accelerance residues R_or [m/(N s)], shape (n_out, n_modes), in ``lsfd_fit``'s convention (the
        accelerance's residue divided by (i w)^2: m/N times rad/s).
    peak_strength
        The selection score: |R_or| w_r / zeta_r of each mode summed over the outputs (about the resonance peaks'
        accelerance) [m/s^2/N], shape (n_modes,).
    order
        The LSCF polynomial order used.
    """

    natural_frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    residues: np.ndarray
    peak_strength: np.ndarray
    order: int


def lscf_poles(frequency_hz: np.ndarray, frf: np.ndarray, order: int, weights: np.ndarray | None = None) -> np.ndarray:
    """Return the poles s_r of a common-denominator rational fit of order ``order``.

    Only poles with positive imaginary part are returned (stable or not).

    Parameters
    ----------
    frequency_hz
        The frequency lines within the analysis band [Hz], shape (n_f,).
    frf
        The complex FRFs [m/s^2/N], shape (n_out, n_f) (the poles do not depend on their unit).
    order
        The polynomial order of the common denominator.
    weights
        Relative weights of each output's lines [-], shape (n_out, n_f); None: all 1.

    Returns
    -------
    poles : np.ndarray
        Complex poles with positive imaginary part [rad/s], shape (n_poles,), n_poles <= order.
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


def residual_terms(frequency_hz: np.ndarray) -> np.ndarray:
    """Return the LSFD's residual terms per unit coefficient on the lines of ``frequency_hz``: 1, w^2 and i w^3.

    The terms of output o are ``coef[o] @ residual_terms(f)``, ``coef`` as ``lsfd_fit`` returns it.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).

    Returns
    -------
    terms : np.ndarray
        Complex rows 1, w^2 and i w^3, w = 2 pi f [-, rad^2/s^2, rad^3/s^3] by row, shape (3, n_f).
    """
    w = 2 * np.pi * np.asarray(frequency_hz, dtype=float)
    return np.array([np.ones_like(w), w**2, 1j * w**3])


def lsfd_fit(frequency_hz: np.ndarray, frf: np.ndarray, poles: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fit the accelerance residues R_or for fixed poles, with lower (constant) and upper residual terms.

    The model is

        H_o(w) = sum_r (iw)^2 [R_or / (iw - s_r) + conj(R_or) / (iw - conj(s_r))] + LR_o + UR_o w^2 + i UI_o w^3

    (LR, UR, UI real; ``residual_terms``). UR w^2 is the mass line of the modes above the band; i UI w^3 is their
    damping's trace in the band (a mode far above, -w^2 phi phi / (w_n^2 - w^2 + 2 i zeta w_n w), adds
    2 i zeta phi phi w^3 / w_n^3). Without it, a structure that damps its high modes strongly (stiffness-proportional:
    zeta 0.2-2 above 2 kHz) left that trace in the residues: 0.5-0.75 % off, and the model updating fitted to them
    moved k_t 7 % and the lever arm 3 % away from the truth (docs/measurements.md).

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    poles
        The fixed complex poles s_r [rad/s], shape (n_poles,).

    Returns
    -------
    residues : np.ndarray
        Complex residues R_or [m/(N s)] (the accelerance's divided by (i w)^2: m/N times rad/s),
        shape (n_out, n_poles).
    coefficients : np.ndarray
        Real residual coefficients LR, UR, UI [m/s^2/N, m/N, m s/N] by column, shape (n_out, 3).
    fitted : np.ndarray
        The fitted complex accelerance [m/s^2/N], shape (n_out, n_f).
    """
    w = 2 * np.pi * np.asarray(frequency_hz, dtype=float)
    iw = 1j * w
    cols = []
    for s in poles:
        a = iw**2 / (iw - s)
        b = iw**2 / (iw - np.conj(s))
        cols += [a + b, 1j * (a - b)]  # Re R and Im R
    A = np.vstack([np.array(cols).reshape(-1, w.size), residual_terms(frequency_hz)]).T
    Areal = np.vstack([A.real, A.imag])
    H = np.atleast_2d(frf)
    n = 2 * len(poles)
    res = np.empty((H.shape[0], len(poles)), dtype=complex)
    coef = np.empty((H.shape[0], 3))
    fit = np.empty_like(H)
    for o in range(H.shape[0]):
        b = np.concatenate([H[o].real, H[o].imag])
        c = np.linalg.lstsq(Areal, b, rcond=None)[0]
        res[o] = c[0:n:2] + 1j * c[1:n:2]
        coef[o] = c[n:]
        fit[o] = A @ c
    return res, coef, fit


def lsfd_residues(frequency_hz: np.ndarray, frf: np.ndarray, poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the residues and the fitted FRF of ``lsfd_fit`` (without its residual coefficients).

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    poles
        The fixed complex poles s_r [rad/s], shape (n_poles,).

    Returns
    -------
    residues : np.ndarray
        Complex residues R_or [m/(N s)], shape (n_out, n_poles), as ``lsfd_fit`` returns them.
    fitted : np.ndarray
        The fitted complex accelerance [m/s^2/N], shape (n_out, n_f).
    """
    res, _, fit = lsfd_fit(frequency_hz, frf, poles)
    return res, fit


def _physical_poles(s: np.ndarray, band_hz: tuple[float, float], max_damping: float) -> np.ndarray:
    """Return the poles ``s`` (rad/s) that are stable, inside ``band_hz`` and with 0 < zeta < ``max_damping``."""
    wn = np.abs(s)
    zeta = -s.real / wn
    keep = (zeta > 0) & (zeta < max_damping) & (wn / (2 * np.pi) >= band_hz[0]) & (wn / (2 * np.pi) <= band_hz[1])
    return s[keep]


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

    Poles from LSCF at ``order`` are kept if stable, inside the band and with 0 < zeta < ``max_damping``; residues
    come from LSFD with all kept poles; the ``n_modes`` with the largest peak strength sum_o |R_or| w_r / zeta_r are
    returned, sorted by frequency.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    n_modes
        How many modes to return.
    band_hz
        The analysis band (low, high) [Hz].
    order
        The LSCF polynomial order.
    max_damping
        The largest damping ratio a physical pole may have [-].
    weights
        Relative LSCF weights of each output's lines [-], shape (n_out, n_f); None: all 1.

    Returns
    -------
    estimate : ModalEstimate
        The ``n_modes`` modes, sorted by frequency.

    Raises
    ------
    ValueError
        When the band holds fewer than 2 ``order`` frequency lines, or fewer than ``n_modes`` physical poles are found.
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
    s = _physical_poles(lscf_poles(fb, Hb, order, Wb), band_hz, max_damping)
    if len(s) < n_modes:
        raise ValueError(f"found {len(s)} physical poles in {band_hz} Hz, {n_modes} requested")
    R, _ = lsfd_residues(fb, Hb, s)
    wn, zeta = np.abs(s), -s.real / np.abs(s)
    strength = np.abs(R).sum(axis=0) * wn / zeta
    top = np.sort(np.argsort(strength)[::-1][:n_modes])
    top = top[np.argsort(wn[top])]
    return ModalEstimate(wn[top] / (2 * np.pi), zeta[top], R[:, top], strength[top], order)


def mode_poles(natural_frequency_hz: np.ndarray, damping_ratio: np.ndarray) -> np.ndarray:
    """Return the poles s_r = -zeta w_n + i w_n sqrt(1 - zeta^2) of identified modes.

    Parameters
    ----------
    natural_frequency_hz
        The modes' undamped natural frequencies f_n = w_n / 2 pi [Hz], shape (n_modes,).
    damping_ratio
        The modes' damping ratios zeta [-], shape (n_modes,).

    Returns
    -------
    poles : np.ndarray
        Complex poles [rad/s], shape (n_modes,).
    """
    wn = 2 * np.pi * np.asarray(natural_frequency_hz, dtype=float)
    z = np.asarray(damping_ratio, dtype=float)
    return -z * wn + 1j * wn * np.sqrt(1 - z**2)


@dataclass(frozen=True)
class StabilityPoles:
    """The physical poles of every model order of a stabilisation diagram, one entry per pole.

    The stable_* flags say whether the nearest pole of the previous order lies within the frequency, damping and
    vector (1 - MAC of the LSFD residue vectors; with one output, the residue's relative change) tolerances.

    Attributes
    ----------
    order
        The LSCF model order of each pole [-], shape (n_poles,), integers.
    frequency_hz
        The pole's undamped natural frequency [Hz], shape (n_poles,).
    damping_ratio
        The pole's damping ratio [-], shape (n_poles,).
    stable_frequency
        Whether it is stable in frequency [-], shape (n_poles,), booleans.
    stable_damping
        Whether it is stable in damping [-], shape (n_poles,), booleans.
    stable_vector
        Whether it is stable in vector [-], shape (n_poles,), booleans.
    """

    order: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    stable_frequency: np.ndarray
    stable_damping: np.ndarray
    stable_vector: np.ndarray

    @property
    def stable(self) -> np.ndarray:
        """Whether each pole is stable in frequency, damping and vector.

        Returns
        -------
        stable : np.ndarray
            Booleans [-], shape (n_poles,).
        """
        return self.stable_frequency & self.stable_damping & self.stable_vector


def _vector_change(a: np.ndarray, b: np.ndarray) -> float:
    """Return 1 - MAC of two residue vectors; for single values the relative change of the residue."""
    if a.size == 1:
        return float(np.abs(a[0] - b[0]) / max(np.abs(b[0]), 1e-300))
    mac = np.abs(np.vdot(a, b)) ** 2 / max((np.vdot(a, a).real * np.vdot(b, b).real), 1e-300)
    return float(1.0 - mac)


def stability_poles(
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    band_hz: tuple[float, float],
    orders: Iterable[int],
    max_damping: float = 0.2,
    tol_frequency: float = 0.01,
    tol_damping: float = 0.05,
    tol_vector: float = 0.02,
) -> StabilityPoles:
    """Return the stabilisation diagram of the LSCF fit.

    For each model order in ``orders`` (increasing) the physical poles in ``band_hz`` (as :func:`fit_modes` keeps
    them), each compared with the nearest pole in frequency of the previous order: stable in frequency when their
    relative difference is within ``tol_frequency``, in damping within ``tol_damping`` (relative) and in vector when
    1 - MAC of their LSFD residue vectors is within ``tol_vector``. Poles of the first order, or without a previous
    pole, are stable in nothing.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    band_hz
        The analysis band (low, high) [Hz].
    orders
        The LSCF model orders, increasing.
    max_damping
        The largest damping ratio a physical pole may have [-].
    tol_frequency
        The relative frequency tolerance [-].
    tol_damping
        The relative damping tolerance [-].
    tol_vector
        The tolerance on 1 - MAC of the residue vectors (one output: on the residue's relative change) [-].

    Returns
    -------
    poles : StabilityPoles
        One entry per physical pole of every order.
    """
    f = np.asarray(frequency_hz, dtype=float)
    sel = (f >= band_hz[0]) & (f <= band_hz[1])
    fb, Hb = f[sel], np.atleast_2d(frf)[:, sel]
    rows, prev = [], None
    for order in orders:
        s = _physical_poles(lscf_poles(fb, Hb, int(order), None), band_hz, max_damping)
        R = lsfd_residues(fb, Hb, s)[0] if len(s) else np.zeros((Hb.shape[0], 0), dtype=complex)
        fn, zeta = np.abs(s) / (2 * np.pi), -s.real / np.abs(s)
        for k in range(len(s)):
            flags = (False, False, False)
            if prev is not None and len(prev[0]):
                j = int(np.argmin(np.abs(prev[0] - fn[k])))
                flags = (
                    abs(fn[k] - prev[0][j]) <= tol_frequency * prev[0][j],
                    abs(zeta[k] - prev[1][j]) <= tol_damping * prev[1][j],
                    _vector_change(R[:, k], prev[2][:, j]) <= tol_vector,
                )
            rows.append((int(order), fn[k], zeta[k], *flags))
        prev = (fn, zeta, R)
    cols = list(zip(*rows)) if rows else [()] * 6
    return StabilityPoles(
        np.array(cols[0], dtype=int),
        np.array(cols[1], dtype=float),
        np.array(cols[2], dtype=float),
        *(np.array(c, dtype=bool) for c in cols[3:]),
    )


def band_residues(
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    natural_frequency_hz: np.ndarray,
    damping_ratio: np.ndarray,
    band_hz: tuple[float, float],
) -> tuple[np.ndarray, np.ndarray]:
    """Return the poles of identified modes (``mode_poles``) and their LSFD residues fitted inside ``band_hz``.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    natural_frequency_hz
        The modes' undamped natural frequencies [Hz], shape (n_modes,).
    damping_ratio
        The modes' damping ratios [-], shape (n_modes,).
    band_hz
        The fitting band (low, high) [Hz].

    Returns
    -------
    poles : np.ndarray
        Complex poles [rad/s], shape (n_modes,).
    residues : np.ndarray
        Complex residues R_or [m/(N s)] (``lsfd_fit``'s convention), shape (n_out, n_modes).
    """
    f = np.asarray(frequency_hz, dtype=float)
    H = np.atleast_2d(frf)
    band = (f >= band_hz[0]) & (f <= band_hz[1])
    poles = mode_poles(natural_frequency_hz, damping_ratio)
    return poles, lsfd_residues(f[band], H[:, band], poles)[0]


def residue_phase_delays(
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    natural_frequency_hz: np.ndarray,
    damping_ratio: np.ndarray,
    band_hz: tuple[float, float],
) -> np.ndarray:
    """Return each output channel's delay on the force from the phase of its LSFD residue at the highest mode.

    A proportionally damped structure has real modes: its accelerance residues R_or (``lsfd_residues`` convention)
    are purely imaginary. A channel late by tau turns its residue at mode r by -w_r tau, so
    tau_o = -arg(R_or / (i sign Im R_or)) / w_r. The highest mode gives the most phase per delay; the low modes'
    residues carry the structure's own complexity (measured on the default rig without a delay: up to 8 degrees at
    the first mode, within 0.07 degrees at the third). On rig records the estimate was within 0.9 us of the rig's
    per-channel delays (2-37 us) and of zero without them (the default data: 0.91, -0.28, -0.76 us with the upper
    residual's damping term, 0.83, -0.21, -0.71 us before it), also on rigs
    whose structure, damping form and normal law differ from the model's (docs/measurements.md). A channel near a
    node of the highest mode (its residue below a tenth of that mode's largest) reads the next mode down where it is
    not; nan where it is at a node of every mode.

    Parameters
    ----------
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The complex accelerance [m/s^2/N], shape (n_out, n_f) (one output may be given as shape (n_f,)).
    natural_frequency_hz
        The identified modes' undamped natural frequencies [Hz], shape (n_modes,).
    damping_ratio
        The identified modes' damping ratios [-], shape (n_modes,).
    band_hz
        The band the residues are fitted in (low, high) [Hz].

    Returns
    -------
    delays : np.ndarray
        Each output's delay on the force [s] (positive: the channel is late), shape (n_out,); NaN at a node of every
        mode.
    """
    fn = np.asarray(natural_frequency_hz, dtype=float)
    wn = 2 * np.pi * fn
    _, R = band_residues(frequency_hz, frf, natural_frequency_hz, damping_ratio, band_hz)
    # a channel near a node of the highest mode (its residue below a tenth of that mode's largest) reads the next
    # mode down where it is not; nan where it is at a node of every mode
    strong = np.abs(R) >= 0.1 * np.abs(R).max(axis=0, keepdims=True)
    tau = np.full(R.shape[0], np.nan)
    for o in range(R.shape[0]):
        usable = [r for r in np.argsort(fn)[::-1] if strong[o, r]]
        if usable:
            r = int(usable[0])
            deviation = np.angle(R[o, r] / (1j * (1.0 if R[o, r].imag >= 0 else -1.0)))
            tau[o] = -deviation / wn[r]
    return tau
