"""Signal processing of raw test records: H1 frequency response and coherence."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FRFEstimate:
    """H1 estimate of each response over the force.

    frequency_hz: (n_f,); h1: (n_out, n_f) complex, response units per N;
    coherence: (n_out, n_f) ordinary coherence (dimensionless);
    n_averages: number of Welch segments.
    """

    frequency_hz: np.ndarray
    h1: np.ndarray
    coherence: np.ndarray
    n_averages: int


def h1_frf(
    force: np.ndarray,
    responses: np.ndarray,
    sampling_rate_hz: float,
    segment_length: int,
    overlap: float = 0.5,
    window: str = "hann",
) -> FRFEstimate:
    """H1 = G_fx / G_ff and coherence |G_fx|^2 / (G_ff G_xx), Welch-averaged.

    force: (n,) in N; responses: (n_out, n) in any unit; returns H1 in
    response unit per N.
    """
    force = np.asarray(force, dtype=float)
    responses = np.atleast_2d(np.asarray(responses, dtype=float))
    n = force.size
    if segment_length > n:
        raise ValueError(f"FRF segment length {segment_length} exceeds the record length {n} samples")
    noverlap = int(round(overlap * segment_length))
    kw = dict(fs=sampling_rate_hz, window=window, nperseg=segment_length, noverlap=noverlap, detrend="constant")
    import scipy.signal  # here: it takes about 0.5 s to import, and most rules never need it

    f, gff = scipy.signal.welch(force, **kw)
    h1 = np.empty((responses.shape[0], f.size), dtype=complex)
    coh = np.empty((responses.shape[0], f.size))
    for i, x in enumerate(responses):
        _, gfx = scipy.signal.csd(force, x, **kw)
        _, gxx = scipy.signal.welch(x, **kw)
        h1[i] = gfx / np.where(gff > 0, gff, np.inf)
        coh[i] = np.abs(gfx) ** 2 / np.where(gff * gxx > 0, gff * gxx, np.inf)
    step = segment_length - noverlap
    n_avg = 1 + (n - segment_length) // step
    return FRFEstimate(f, h1, coh, int(n_avg))
