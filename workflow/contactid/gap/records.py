"""Harmonics of the measured dual-sine records, the quantities every comparison uses.

A record x(t) is summarised by its complex harmonics c_h (h = 1..H) of the test frequency,
x ~ mean + sum_h Im(c_h e^{i h w t}) (as in Eq. 16), estimated over whole periods. Time zero is
moved to the force's fundamental's zero crossing (phase of c_1 of the force = 0), so records
and simulations share one time origin; a common delay of all channels (anti-alias filter)
drops out. Block estimates (the record cut into whole-period blocks) give the spread for the
bootstrap, and the first and last thirds show drift. The share of each accelerometer's response that no harmonic
of the drive explains shows whether the record settled (its noise alone) or not (impacts, chaos).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..harmonics import aperiodic_share, harmonic_amplitudes


@dataclass(frozen=True)
class RecordHarmonics:
    """One load case's record in harmonics.

    The harmonics c_h (h = 1..H) are complex amplitudes in the signal's unit, x ~ mean + sum_h Im(c_h e^{i h w t}),
    with time zero where the force's fundamental has phase 0; H harmonics, j accelerometers, B blocks of whole
    periods.

    Attributes
    ----------
    case
        The load case's name (e.g. ``lc1``).
    f0
        The excitation (test) frequency [Hz], as the record declares it.
    fs
        The sampling rate [Hz].
    periods
        Whole periods of the test frequency in the record.
    force
        The force's harmonics [N], complex, shape (H,).
    acceleration
        Each accelerometer's harmonics [m/s^2], complex, shape (j, H).
    block_force
        The force's harmonics per block of whole periods [N], complex, shape (B, H).
    block_acceleration
        The accelerations' harmonics per block [m/s^2], complex, shape (B, j, H).
    first
        The accelerations' harmonics over the record's first third [m/s^2], complex, shape (j, H).
    last
        The accelerations' harmonics over the record's last third [m/s^2], complex, shape (j, H).
    sensors
        The accelerometers' names, j of them.
    aperiodic
        Each accelerometer's share of its rms that is not periodic at the drive frequency [-], shape (j,)
        (``harmonics.aperiodic_share`` at the frequency the force record shows: the noise alone where the response
        settles); None where not computed.
    """

    case: str
    f0: float
    fs: float
    periods: int
    force: np.ndarray
    acceleration: np.ndarray
    block_force: np.ndarray
    block_acceleration: np.ndarray
    first: np.ndarray
    last: np.ndarray
    sensors: tuple
    aperiodic: np.ndarray | None = None


def _aligned(force_coef: np.ndarray, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shift time so that the force's fundamental has phase 0: c_h -> c_h e^{-i h phi_1}."""
    h = np.arange(1, force_coef.shape[-1] + 1)
    rot = np.exp(-1j * h * np.angle(force_coef[..., :1]))
    return force_coef * rot, coefs * rot[..., None, :] if coefs.ndim == force_coef.ndim + 1 else coefs * rot


def _harmonics(x: np.ndarray, t: np.ndarray, w: float, H: int) -> np.ndarray:
    """Return harmonics 1..H of every row of x, one least-squares solve for all rows (one design matrix)."""
    return harmonic_amplitudes(np.atleast_2d(x).T, t, w, range(1, H + 1)).T


def record_harmonics(raw: xr.Dataset, case: str, n_harmonics: int, n_blocks: int = 8) -> RecordHarmonics:
    """Return harmonics 1..n_harmonics of the force and every accelerometer of a dual-sine record.

    They are estimated over the record's whole periods, over each of ``n_blocks`` blocks of whole periods and over
    its first and last thirds, each aligned so that the force's fundamental has phase 0.

    Parameters
    ----------
    raw
        The raw dual-sine record: ``force`` (time) [N] and ``acceleration`` (sensor, time) [m/s^2], the ``sensor``
        names, attributes ``sampling_rate_hz`` and ``excitation_frequency_hz``.
    case
        The load case's name.
    n_harmonics
        How many harmonics of the test frequency, H.
    n_blocks
        Blocks of whole periods for the block estimates (at least 2, at most the record's periods).

    Returns
    -------
    record : RecordHarmonics
        The record's harmonics.
    """
    fs = float(raw.attrs["sampling_rate_hz"])
    f0 = float(raw.attrs["excitation_frequency_hz"])
    force = raw["force"].values
    acc = raw["acceleration"].values
    n = force.size
    per = fs / f0
    periods = int(np.floor(n / per + 1e-9))
    n_use = int(round(periods * per)) if periods * per <= n + 1e-6 else n
    t = np.arange(n_use) / fs
    w = 2 * np.pi * f0
    H = int(n_harmonics)
    F = _harmonics(force[:n_use], t, w, H)[0]
    A = _harmonics(acc[:, :n_use], t, w, H)
    F_al, A_al = _aligned(F, A)
    n_blocks = max(2, min(int(n_blocks), periods))
    edges = np.round(np.arange(n_blocks + 1) * (periods // n_blocks) * per).astype(int)
    bf, ba = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        fb = _harmonics(force[a:b], t[a:b], w, H)[0]
        ab = _harmonics(acc[:, a:b], t[a:b], w, H)
        fb, ab = _aligned(fb, ab)
        bf.append(fb)
        ba.append(ab)
    third = int(round((periods // 3) * per))
    thirds = []
    for sl in (slice(0, third), slice(n_use - third, n_use)):
        ft = _harmonics(force[sl], t[sl], w, H)[0]
        at = _harmonics(acc[:, sl], t[sl], w, H)
        thirds.append(_aligned(ft, at)[1])
    return RecordHarmonics(
        case,
        f0,
        fs,
        periods,
        F_al,
        A_al,
        np.array(bf),
        np.array(ba),
        thirds[0],
        thirds[1],
        tuple(str(s) for s in raw["sensor"].values),
        aperiodic_share(acc[:, :n_use], fs, _drive_frequency(force, fs, f0)),
    )


def _drive_frequency(force: np.ndarray, fs: float, declared_hz: float) -> float:
    """Return the drive's frequency as the force record shows it (``raw_checks_dual_sine.recovered_frequency``).

    It serves the share of the response that is not periodic: a declared frequency off by the raw checks' tolerance
    (0.02 cycles over the record) would leave 4 % of the fundamental and more of each higher harmonic unfitted, a
    settled record read as one that does not settle. The declared one where the record's strongest line is not one of
    its first three harmonics.
    """
    from ..raw_checks_dual_sine import recovered_frequency

    f, h = recovered_frequency(np.asarray(force, dtype=float), fs, declared_hz)
    return f if h in (1, 2, 3) and abs(f / declared_hz - 1.0) < 0.01 else declared_hz
