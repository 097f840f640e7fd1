"""Signal processing of raw test records: H1 frequency response and coherence."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ARRAY_LIMIT_BYTES = 256 << 20
"""The most memory (bytes, 256 MiB) the Welch segments' spectra of ``h1_frf`` may take at once: a longer record's
segments are transformed and averaged in batches that stay below it (the same spectra, their means to rounding),
so the FRF's memory does not grow with the record. A single segment past it (``frf.segment_length`` x the channels:
some 2.8 million samples of four channels) is refused with ``io.WorkLimitError``. The project's random test (128 s at
5120 Hz, segments of 65536 samples, four channels) takes 76 MiB, the foreign records' (60 s at 5400 Hz, 32768
samples) 36 MiB: both in one batch, as before."""


def _segment_bytes(n_channels: int, segment_length: int) -> int:
    """Return the memory (bytes) of one segment's work in ``segment_spectra``.

    It counts the detrended, windowed copy (8 bytes a sample) and its one-sided spectrum (16 bytes a bin) of every
    channel.
    """
    return int(n_channels) * (8 * int(segment_length) + 16 * (int(segment_length) // 2 + 1))


@dataclass(frozen=True)
class FRFEstimate:
    """H1 estimate of each response over the force.

    Attributes
    ----------
    frequency_hz
        Frequencies of the spectral lines [Hz], shape (n_f,), n_f = segment_length // 2 + 1 lines from 0 to half
        the sampling rate.
    h1
        H1 estimate of each response over the force, complex, in the response's unit per newton (accelerances
        [m/s^2/N] for accelerations), shape (n_out, n_f), n_out the responses.
    coherence
        Ordinary coherence of each response with the force [-], shape (n_out, n_f).
    n_averages
        Number of Welch segments averaged.
    """

    frequency_hz: np.ndarray
    h1: np.ndarray
    coherence: np.ndarray
    n_averages: int


def segment_spectra(x: np.ndarray, segment_length: int, step: int, window: str) -> np.ndarray:
    """Return the one-sided spectra (rfft) of Welch's segments of each row of ``x``.

    The segments are ``segment_length`` samples every ``step`` (the whole segments only, as scipy.signal.welch takes
    them), each less its mean (``detrend="constant"``) and times ``window`` (``periodic_window``).

    Parameters
    ----------
    x
        Sampled signals, one channel per row, each in its own unit (e.g. [N] for a force, [m/s^2] for an
        acceleration), shape (n_channels, n), n samples.
    segment_length
        Samples per segment.
    step
        Samples from one segment's start to the next's.
    window
        Name of the window (``scipy.signal.get_window``'s, e.g. ``hann``).

    Returns
    -------
    spectra : np.ndarray
        Unscaled complex spectra [unit of x], shape (n_channels, n_segments, segment_length // 2 + 1), n_segments
        = 1 + (n - segment_length) // step.
    """
    from numpy.lib.stride_tricks import sliding_window_view

    n_seg = 1 + (x.shape[-1] - segment_length) // step
    segs = sliding_window_view(x, segment_length, axis=-1)[:, : (n_seg - 1) * step + 1 : step]
    segs = segs - segs.mean(axis=-1, keepdims=True)
    segs *= periodic_window(window, segment_length)
    return np.fft.rfft(segs, axis=-1)


def periodic_window(window: str, n: int) -> np.ndarray:
    """Return scipy.signal.get_window(window, n), the periodic window of Welch's segments.

    The Hann window (the config's default) is computed here as 0.5 - 0.5 cos(2 pi k / n), within 2.3e-16 of scipy's,
    without importing scipy.signal (1.2 s here).

    Parameters
    ----------
    window
        Name of the window (``scipy.signal.get_window``'s, e.g. ``hann``).
    n
        Samples of the window (the segment length).

    Returns
    -------
    weights : np.ndarray
        The window's weights [-], shape (n,).
    """
    if window == "hann":
        return 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    from scipy.signal import get_window

    return get_window(window, n)


def h1_frf(
    force: np.ndarray,
    responses: np.ndarray,
    sampling_rate_hz: float,
    segment_length: int,
    overlap: float = 0.5,
    window: str = "hann",
) -> FRFEstimate:
    """Return the Welch-averaged H1 = G_fx / G_ff of each response and its coherence |G_fx|^2 / (G_ff G_xx).

    The auto and cross spectra are those of scipy.signal.welch and csd (mean over the segments); their common scaling
    (density, one-sided) cancels in H1 and the coherence, which are formed here from each channel's segment spectra
    computed once (``segment_spectra``) instead of once per spectrum that reads them (the force's four times for three
    responses): the same numbers to rounding in 40 % of the time. A record whose segments' spectra would take more
    than ``ARRAY_LIMIT_BYTES`` is transformed in batches below it.

    Parameters
    ----------
    force
        The excitation force [N], shape (n,), n samples.
    responses
        The responses, in any unit (accelerations [m/s^2] in the project), shape (n_out, n), or (n,) for one.
    sampling_rate_hz
        The records' sampling rate [Hz].
    segment_length
        Samples per Welch segment (``frf.segment_length``).
    overlap
        Overlap of consecutive segments, a fraction of ``segment_length`` [-] (``frf.overlap``).
    window
        Name of the window (``frf.window``; ``periodic_window``).

    Returns
    -------
    estimate : FRFEstimate
        H1 in the response's unit per newton and the coherence on the segments' lines, with the number of segments.

    Raises
    ------
    ValueError
        When ``segment_length`` exceeds the record's length.
    WorkLimitError
        When one segment's work of all channels exceeds ``ARRAY_LIMIT_BYTES`` (``io.WorkLimitError``).
    """
    force = np.asarray(force, dtype=float)
    responses = np.atleast_2d(np.asarray(responses, dtype=float))
    n = force.size
    if segment_length > n:
        raise ValueError(f"FRF segment length {segment_length} exceeds the record length {n} samples")
    noverlap = int(round(overlap * segment_length))
    step = segment_length - noverlap
    x = np.vstack([force, responses])
    n_seg = 1 + (n - segment_length) // step
    per_segment = _segment_bytes(x.shape[0], segment_length)
    if per_segment > ARRAY_LIMIT_BYTES:
        from .io import WorkLimitError

        raise WorkLimitError(
            f"FRF: one Welch segment of {segment_length} samples (frf.segment_length; "
            f"{sampling_rate_hz / segment_length:.3g} Hz resolution at {sampling_rate_hz:g} Hz) of {x.shape[0]} "
            f"channels needs {per_segment / 2**20:.4g} MiB, "
            f"above the limit of {ARRAY_LIMIT_BYTES / 2**20:g} MiB (contactid.signals.ARRAY_LIMIT_BYTES): give a "
            "shorter frf.segment_length, or check the record's sampling_rate_hz"
        )
    batch = max(1, ARRAY_LIMIT_BYTES // per_segment)
    if n_seg <= batch:
        spectra = segment_spectra(x, segment_length, step, window)
        F, X = spectra[0], spectra[1:]
        gff = np.mean(F.real**2 + F.imag**2, axis=0)
        gfx = np.mean(np.conj(F)[None] * X, axis=1)
        gxx = np.mean(X.real**2 + X.imag**2, axis=1)
    else:  # a long record: its segments in batches below the limit, the spectra's sums accumulated
        n_bin = segment_length // 2 + 1
        gff, gfx, gxx = np.zeros(n_bin), np.zeros((x.shape[0] - 1, n_bin), complex), np.zeros((x.shape[0] - 1, n_bin))
        for first in range(0, n_seg, batch):
            last = min(n_seg, first + batch)
            part = x[:, first * step : (last - 1) * step + segment_length]
            spectra = segment_spectra(part, segment_length, step, window)
            F, X = spectra[0], spectra[1:]
            gff += np.sum(F.real**2 + F.imag**2, axis=0)
            gfx += np.sum(np.conj(F)[None] * X, axis=1)
            gxx += np.sum(X.real**2 + X.imag**2, axis=1)
        gff, gfx, gxx = gff / n_seg, gfx / n_seg, gxx / n_seg
    h1 = gfx / np.where(gff > 0, gff, np.inf)
    coh = np.abs(gfx) ** 2 / np.where(gff * gxx > 0, gff * gxx, np.inf)
    f = np.fft.rfftfreq(segment_length, 1.0 / sampling_rate_hz)
    return FRFEstimate(f, h1, coh, int(n_seg))
