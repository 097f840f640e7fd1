"""Harmonics of periodic signals in one convention: x(t) ~ mean + sum_h Im(c_h e^{i h w t}), h = 1, 2, ...

Here w = 2 pi f0 rad/s and c_h is complex, in the signal's units. Analysis by least squares on any window
(``harmonic_amplitudes``, ``harmonic_content``, ``fourier_series``, Eq. 16) or by FFT of whole periods
(``periodic_harmonics``); synthesis at any times, with analytic derivatives and integrals (``synthesize``, Eq. 17), or
on a grid over one period (``periodic_grid``). Every module that analyses or synthesises harmonics uses these.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

ARRAY_LIMIT_BYTES = 256 << 20
"""The most memory (bytes, 256 MiB) one work array of this module sized by a record may take: the least-squares
design matrix of ``harmonic_amplitudes`` (samples x (2 harmonics + 1), with its two complex powers) and the phase
matrix of ``synthesize`` (harmonics x samples, complex). ``aperiodic_share`` fits every harmonic below 0.45 fs, so its
design matrix grows with the square of the samples per period: 12 MiB on the project's records (174 periods of 94
samples), 14 GiB on two million samples at 1000 samples per period. Past the limit the work is done in blocks of
samples below it (the normal equations summed block by block, the synthesis block by block: the same numbers to
rounding), where a least squares by SVD is needed (fewer than two periods, aliased or repeated harmonics) refused
with ``io.WorkLimitError``."""


def _design_row_bytes(n_columns: int) -> int:
    """Return the memory (bytes) per sample of ``harmonic_amplitudes``' design matrix and its complex powers."""
    return 8 * int(n_columns) + 32


def _design(t: np.ndarray, w: float, harmonics: list) -> np.ndarray:
    """Return the least-squares design matrix [1, sin(h w t), cos(h w t)...] (t.size, 1 + 2 len(harmonics))."""
    # e^{i h w t} by powers of e^{i w t} (about h machine epsilons of error, a tenth of the cost of sin and cos)
    X = np.empty((t.size, 1 + 2 * len(harmonics)))
    X[:, 0] = 1.0
    z = np.exp(1j * w * t)
    zh = np.ones_like(z)
    for h in range(1, max(harmonics, default=0) + 1):
        zh = zh * z
        for k in (k for k, hk in enumerate(harmonics) if hk == h):
            X[:, 1 + 2 * k], X[:, 2 + 2 * k] = zh.imag, zh.real
    return X


def harmonic_amplitudes(signal: np.ndarray, t: np.ndarray, w: float, harmonics: Iterable[int]) -> np.ndarray:
    """Return the complex amplitudes c_h of signal ~ mean + sum_h Im(c_h exp(i h w t)) by least squares.

    Valid on any window, a whole number of periods or not. Several signals sampled at the same times are solved
    together. The memory stays within ``ARRAY_LIMIT_BYTES``: past it the normal equations are summed over blocks of
    samples.

    Parameters
    ----------
    signal
        The samples, in any unit (e.g. [N], [m/s^2]), shape (n_t,), or (n_t, k) for k signals sampled at the same
        times.
    t
        The sampling times [s], shape (n_t,).
    w
        The fundamental angular frequency [rad/s].
    harmonics
        The harmonic numbers h (1 the fundamental).

    Returns
    -------
    coef : np.ndarray
        The complex amplitudes c_h, in the order of ``harmonics`` [unit of signal], shape (n_harmonics,), or
        (n_harmonics, k) for k signals.

    Raises
    ------
    WorkLimitError
        Where the design matrix passes ``ARRAY_LIMIT_BYTES`` and the least squares cannot be done in blocks (fewer
        than two periods, or harmonics repeated or above the Nyquist frequency).
    """
    harmonics = [int(h) for h in harmonics]
    t = np.asarray(t, dtype=float)
    n_columns = 1 + 2 * len(harmonics)
    span = t[-1] - t[0] if t.size > 1 else 0.0
    periods = span * w / (2 * np.pi)
    # the highest harmonic's phase advance per sample, against pi (Nyquist: its sine column would vanish)
    top = max(harmonics, default=0) * w * span / max(t.size - 1, 1)
    normal = periods >= 2.0 and t.size > 4 * n_columns and len(set(harmonics)) == len(harmonics) and top < 0.9 * np.pi
    rows = max(1, ARRAY_LIMIT_BYTES // _design_row_bytes(n_columns))
    if t.size <= rows:
        X = _design(t, w, harmonics)
        if normal:
            # two periods or more of distinct harmonics below Nyquist: the columns are near orthogonal (condition
            # about 1.4), so the normal equations are as accurate as an SVD (1e-16) at a third of its cost; otherwise
            # the SVD least squares (a repeated or aliased harmonic: the minimum-norm solution, as before)
            import scipy.linalg

            coef = scipy.linalg.solve(X.T @ X, X.T @ signal, assume_a="pos", check_finite=False)
        else:
            coef = np.linalg.lstsq(X, signal, rcond=None)[0]
    elif normal:  # a design matrix past the limit: the normal equations summed over blocks of samples
        import scipy.linalg

        signal = np.asarray(signal)
        XtX = np.zeros((n_columns, n_columns))
        Xty = np.zeros((n_columns,) + signal.shape[1:], dtype=np.result_type(signal, float))
        for first in range(0, t.size, rows):
            X = _design(t[first : first + rows], w, harmonics)
            XtX += X.T @ X
            Xty += X.T @ signal[first : first + rows]
        coef = scipy.linalg.solve(XtX, Xty, assume_a="pos", check_finite=False)
    else:
        from .io import WorkLimitError

        raise WorkLimitError(
            f"harmonic analysis: a least squares of {len(harmonics)} harmonics on {t.size} samples "
            f"({periods:.3g} periods) needs {t.size * _design_row_bytes(n_columns) / 2**20:.4g} MiB, above the limit "
            f"of {ARRAY_LIMIT_BYTES / 2**20:g} MiB (contactid.harmonics.ARRAY_LIMIT_BYTES), and it cannot be done in "
            "blocks (fewer than two periods, or harmonics repeated or above the Nyquist frequency): check the record's "
            "sampling_rate_hz and excitation_frequency_hz"
        )
    # Im(c e^{i h w t}) = Re(c) sin + Im(c) cos
    return coef[1::2] + 1j * coef[2::2]


def harmonic_content(
    signal: np.ndarray, sampling_rate_hz: float, frequency_hz: float, harmonics: Iterable[int]
) -> np.ndarray:
    """Return the complex harmonic amplitudes of a record sampled from t = 0 (see :func:`harmonic_amplitudes`).

    |c_h| is the amplitude of harmonic h of ``frequency_hz``.

    Parameters
    ----------
    signal
        The record's samples, in any unit (e.g. [N], [m/s^2]), shape (n_t,), or (n_t, k) for k signals sampled at
        the same times.
    sampling_rate_hz
        The sampling rate [Hz].
    frequency_hz
        The fundamental frequency [Hz].
    harmonics
        The harmonic numbers h (1 the fundamental).

    Returns
    -------
    coef : np.ndarray
        The complex amplitudes c_h, in the order of ``harmonics`` [unit of signal], shape (n_harmonics,), or
        (n_harmonics, k) for k signals.
    """
    t = np.arange(len(signal)) / sampling_rate_hz
    return harmonic_amplitudes(signal, t, 2 * np.pi * frequency_hz, harmonics)


def fourier_series(signals: np.ndarray, fs: float, f0: float, n_harmonics: int) -> np.ndarray:
    """Return the complex harmonic amplitudes c_h (h = 1..K) of each row, signal ~ mean + sum Im(c_h e^{i h w t}).

    Eq. 16, by least squares on each row sampled from t = 0 (``harmonic_content``).

    Parameters
    ----------
    signals
        The records, one a row, in any unit (e.g. [N], [m/s^2]), shape (n_signals, n_t), or (n_t,) for one.
    fs
        The sampling rate [Hz].
    f0
        The fundamental frequency [Hz].
    n_harmonics
        K, the number of harmonics.

    Returns
    -------
    coef : np.ndarray
        The complex amplitudes c_1..c_K of each row [unit of signals], shape (n_signals, n_harmonics).
    """
    h = np.arange(1, n_harmonics + 1)
    return np.array([harmonic_content(x, fs, f0, h) for x in np.atleast_2d(signals)])


def positive_spectrum(x: np.ndarray, H: int) -> np.ndarray:
    """Return the DFT bins 1..H of each row of ``x`` (along its last axis).

    By the real FFT where x is real and H lies below the Nyquist bin (the same values to rounding, a fifth to a half of
    the complex FFT's time: 0.2 against 0.9 ms for the inverse identification's 99 x 200 grids), else by the complex
    FFT.

    Parameters
    ----------
    x
        The samples along the last axis, in any unit (e.g. [N], [m/s^2]), shape (..., n_samples).
    H
        The highest bin returned.

    Returns
    -------
    bins : np.ndarray
        The (unnormalised) DFT bins 1..H [unit of x], shape (..., H).
    """
    n = x.shape[-1]
    if np.isrealobj(x) and H <= n // 2:
        return np.fft.rfft(x, axis=-1)[..., 1 : H + 1]
    return np.fft.fft(x, axis=-1)[..., 1 : H + 1]


def periodic_harmonics(x: np.ndarray, t_first: float, w: float, n_per: int, H: int) -> np.ndarray:
    """Return the harmonics 1..H (x ~ mean + sum Im(c_h e^{i h w t})) of rows sampled over whole periods.

    The rows are sampled uniformly over a whole number of periods of n_per samples each, the first at t_first (exact, by
    FFT of the period mean; samples past the last whole period are left out).

    Parameters
    ----------
    x
        The samples, one signal a row, in any unit (e.g. [N], [m/s^2]), shape (n_rows, n_samples), or (n_samples,)
        for one.
    t_first
        The time of the first sample [s].
    w
        The fundamental angular frequency [rad/s].
    n_per
        The samples per period.
    H
        The number of harmonics.

    Returns
    -------
    coef : np.ndarray
        The complex amplitudes c_1..c_H of each row [unit of x], shape (n_rows, H).
    """
    x = np.atleast_2d(x)
    periods = x.shape[1] // n_per
    mean_period = x[:, : periods * n_per].reshape(x.shape[0], periods, n_per).mean(axis=1)
    X = positive_spectrum(mean_period, H)
    h = np.arange(1, H + 1)
    return 2j * X / n_per * np.exp(-1j * h * w * t_first)


def aperiodic_share(x: np.ndarray, fs: float, f0: float, band: float = 0.45) -> np.ndarray:
    """Return the share of each row's rms (about its mean) that is not periodic at f0.

    What is left once the mean and every harmonic of f0 below ``band`` x fs are fitted (least squares over the whole
    periods of the record, x sampled at fs from t = 0). A periodic response leaves the sensors' noise alone (the noise
    fraction, 0.005 on the rig); a motion that does not settle (impacts, chaos) leaves far more (0.2-0.5 on a separating
    contact's record).

    Parameters
    ----------
    x
        The records, one a row, in any unit (e.g. [N], [m/s^2]), shape (n_rows, n_samples), or (n_samples,) for one.
    fs
        The sampling rate [Hz].
    f0
        The fundamental frequency [Hz].
    band
        The highest harmonic fitted, as a fraction of ``fs`` [-].

    Returns
    -------
    share : np.ndarray
        The aperiodic rms over the rms about the mean, per row [-], shape (n_rows,).
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    periods = int(np.floor(x.shape[1] * f0 / fs + 1e-9))
    n = min(x.shape[1], int(round(periods * fs / f0))) if periods >= 2 else x.shape[1]
    x = x[:, :n]
    scale = np.max(np.abs(x), axis=1, keepdims=True)  # the share is scale-free: no overflow on a diverging response
    x = x / np.where(scale > 0, scale, 1.0)
    t = np.arange(n) / fs
    H = max(1, int(band * fs / f0))
    c = harmonic_amplitudes(x.T, t, 2 * np.pi * f0, range(1, H + 1)).T
    centred = x - x.mean(axis=1, keepdims=True)
    left = centred - synthesize(c, f0, t)
    left -= left.mean(axis=1, keepdims=True)
    return np.sqrt(np.mean(left**2, axis=1) / np.maximum(np.mean(centred**2, axis=1), 1e-300))


def synthesize(coef: np.ndarray, f0: float, t: np.ndarray, derivative: int = 0) -> np.ndarray:
    """Return the time signals sum_h Im(c_h (i h w)^d e^{i h w t}) of harmonic coefficients (Eq. 17).

    With d the ``derivative``: d = -2 integrates twice analytically. Past ``ARRAY_LIMIT_BYTES`` the synthesis is done
    block by block.

    Parameters
    ----------
    coef
        The complex amplitudes c_1..c_K of each row, in any unit (e.g. [N], [m/s^2]), shape (n_rows, K), or (K,) for
        one.
    f0
        The fundamental frequency [Hz].
    t
        The times [s], shape (n_t,).
    derivative
        d, the order of the time derivative (negative: integrals).

    Returns
    -------
    signals : np.ndarray
        The signals [unit of coef] times s^-d (d = -2: [unit of coef] s^2), shape (n_rows, n_t).
    """
    coef = np.atleast_2d(coef)
    h = np.arange(1, coef.shape[1] + 1)
    w = 2 * np.pi * f0
    factor = (1j * h * w) ** derivative
    t = np.asarray(t, dtype=float)
    block = max(1, ARRAY_LIMIT_BYTES // (24 * h.size))  # samples whose phases (real) and exponentials (complex) fit
    if t.size <= block:
        return np.imag((coef * factor) @ np.exp(1j * np.outer(h * w, t)))
    return np.concatenate(  # past ``ARRAY_LIMIT_BYTES``: block by block
        [np.imag((coef * factor) @ np.exp(1j * np.outer(h * w, t[i : i + block]))) for i in range(0, t.size, block)],
        axis=-1,
    )


def periodic_grid(coef: np.ndarray, f0: float, m: int, derivative: int = 0) -> np.ndarray:
    """Return K-harmonic periodic signals synthesised on ``m`` points of one period, t = n / (m f0).

    The signals x ~ sum Im(c (i h w)^d e^{ihwt}) of rows of complex coefficients, by Fourier interpolation:
    ``synthesize`` on that grid, by one inverse real FFT per row where m > 2 K (the same values to rounding, about 1e-15
    of the signal, 4-30 times faster than the matrix product).

    Parameters
    ----------
    coef
        The complex amplitudes c_1..c_K of each row, in any unit (e.g. [N], [m/s^2]), shape (n_rows, K), or (K,) for
        one.
    f0
        The fundamental frequency [Hz].
    m
        The number of points over the period.
    derivative
        d, the order of the time derivative (negative: integrals).

    Returns
    -------
    signals : np.ndarray
        The signals at t = n / (m f0), n = 0..m-1 [unit of coef] times s^-d, shape (n_rows, m).
    """
    coef = np.atleast_2d(coef)
    K = coef.shape[1]
    if m <= 2 * K:
        return synthesize(coef, f0, np.arange(m) / (m * f0), derivative)
    c = coef * (1j * np.arange(1, K + 1) * 2 * np.pi * f0) ** derivative
    # Im(c e^{i theta}) = Re(c) sin(theta) + Im(c) cos(theta) = Re((Im c - i Re c) e^{i theta}); irfft halves its
    # coefficients' weight at 1..m/2-1 and divides by m
    X = np.zeros((coef.shape[0], m // 2 + 1), dtype=complex)
    X[:, 1 : K + 1] = (c.imag - 1j * c.real) * (m / 2)
    return np.fft.irfft(X, n=m, axis=1)
