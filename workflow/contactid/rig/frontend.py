"""The virtual rig's data-acquisition front end: channel delays, anti-alias filtering and decimation, sensor noise."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.signal


def anti_alias_decimate(x: np.ndarray, q: int) -> np.ndarray:
    """Filter with a zero-phase linear-phase FIR anti-alias filter and decimate by ``q`` along the last axis.

    The filter is flat (within 0.1 dB) to 0.4 of the output rate, -60 dB beyond its Nyquist frequency, and the same on
    every channel (as a sigma-delta front end).

    Parameters
    ----------
    x
        Signals sampled at the simulation's rate, in any unit (the rig's force [N], its accelerations [m/s^2]),
        shape (..., n_samples): filtered along the last axis.
    q
        Decimation factor (simulation steps per output sample); 1 returns ``x`` as it is.

    Returns
    -------
    decimated : np.ndarray
        The filtered signals at every ``q``-th sample [unit of x], shape (..., ceil(n_samples / q)).
    """
    if q == 1:
        return np.asarray(x)
    taps = scipy.signal.firwin(48 * q + 1, 0.45 / q * 2, window=("kaiser", 7.0))
    # odd-length symmetric taps convolved 'same': linear phase with the delay removed
    y = scipy.signal.oaconvolve(x, taps[(None,) * (np.ndim(x) - 1)], mode="same", axes=-1)
    return y[..., ::q]


def delay_channels(x: np.ndarray, delays_s: Sequence[float] | np.ndarray, fs: float) -> np.ndarray:
    """Delay each row of ``x`` by its delay with an FFT fractional-delay shift.

    The ends wrap: pad before calling.

    Parameters
    ----------
    x
        Signals, one channel a row, in any unit (the rig's accelerations [m/s^2]), shape (n_channels, n_samples); a
        single channel of shape (n_samples,) is taken as one row.
    delays_s
        Each channel's delay [s], shape (n_channels,).
    fs
        Sampling rate of ``x`` [Hz].

    Returns
    -------
    delayed : np.ndarray
        The delayed signals [unit of x], shape (n_channels, n_samples).
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    f = np.fft.rfftfreq(n, 1.0 / fs)
    X = np.fft.rfft(x, axis=-1)
    X *= np.exp(-2j * np.pi * f[None, :] * np.asarray(delays_s, dtype=float)[:, None])
    return np.fft.irfft(X, n, axis=-1)


def add_noise(x: np.ndarray, fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Add independent Gaussian noise to each channel, its rms ``fraction`` times the channel's rms about its mean.

    Parameters
    ----------
    x
        Signals, one channel a row along the last axis, in any unit (the rig's force [N], its accelerations
        [m/s^2]), shape (..., n_samples).
    fraction
        Noise rms relative to each channel's rms about its mean [-].
    rng
        Random generator of the noise.

    Returns
    -------
    noisy : np.ndarray
        The signals with the noise added [unit of x], shape (..., n_samples).
    """
    x = np.asarray(x, dtype=float)
    scale = fraction * np.std(x, axis=-1, keepdims=True)
    return x + scale * rng.standard_normal(x.shape)
