"""The data-acquisition front end of the virtual rig: channel delays, anti-alias
filtering and decimation, sensor noise."""

from __future__ import annotations

import numpy as np
import scipy.signal


def anti_alias_decimate(x: np.ndarray, q: int) -> np.ndarray:
    """Zero-phase linear-phase FIR anti-alias filter and decimation by ``q`` along the last
    axis: flat (within 0.1 dB) to 0.4 of the output rate, -60 dB beyond its Nyquist frequency,
    the same on every channel (as a sigma-delta front end)."""
    if q == 1:
        return np.asarray(x)
    taps = scipy.signal.firwin(48 * q + 1, 0.45 / q * 2, window=("kaiser", 7.0))
    # odd-length symmetric taps convolved 'same': linear phase with the delay removed
    y = scipy.signal.oaconvolve(x, taps[(None,) * (np.ndim(x) - 1)], mode="same", axes=-1)
    return y[..., ::q]


def delay_channels(x: np.ndarray, delays_s, fs: float) -> np.ndarray:
    """Delay each row of ``x`` (channels, samples) by its delay (s) with an FFT
    fractional-delay shift (the ends wrap: pad before calling)."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    f = np.fft.rfftfreq(n, 1.0 / fs)
    X = np.fft.rfft(x, axis=-1)
    X *= np.exp(-2j * np.pi * f[None, :] * np.asarray(delays_s, dtype=float)[:, None])
    return np.fft.irfft(X, n, axis=-1)


def add_noise(x: np.ndarray, fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Independent Gaussian noise per channel, rms = fraction x the channel's rms (about its mean)."""
    x = np.asarray(x, dtype=float)
    scale = fraction * np.std(x, axis=-1, keepdims=True)
    return x + scale * rng.standard_normal(x.shape)
