"""Checks of raw records before identification that the dual-sine records and the random test share.

The config's raw_checks with the schema's defaults, the checks' thresholds (the constants below, from the physics and
statistics of the records) and the checks of every channel (magnitude, dead channels, clipping, offsets).

The dual-sine records' own checks are in ``raw_checks_dual_sine``, the random test's in ``raw_checks_random``.
"""

from __future__ import annotations

from typing import Iterator, Mapping, Sequence

import numpy as np
import xarray as xr

from .io import RawDataError

# ------------------------------------------------------------------------------------------
# validation of raw records before identification (config raw_checks); a failure stops the
# record with a message naming the file, the channel, the check and the measured value; a value
# beyond half its limit is a warning stored in the check dataset and shown in the report
# ------------------------------------------------------------------------------------------


def check_settings(checks: Mapping | None) -> dict:
    """Return raw_checks with the schema's defaults filled in (max_harmonic and min_periods, the reader's, apart).

    Parameters
    ----------
    checks
        The config's ``raw_checks`` section (None or keys left out or null: the schema's defaults): clip_samples,
        frequency_tolerance_cycles, stationarity_tolerance, drift_tolerance, min_coherence, coherence_fraction and
        max_frf_resolution_hz.

    Returns
    -------
    settings : dict
        The schema's raw_checks defaults (but max_harmonic and min_periods) with the keys ``checks`` sets over them.
    """
    from .schema import schema_defaults

    defaults = {k: v for k, v in schema_defaults("raw_checks").items() if k not in ("max_harmonic", "min_periods")}
    return {**defaults, **{k: v for k, v in dict(checks or {}).items() if v is not None}}


# no force (N) or acceleration (m/s^2) of a vibration test comes near this: a larger value is a scaling error
PHYSICAL_LIMIT = 1.0e9

# The checks' thresholds, from the physics and statistics of the records (none is a setting):
# - a bin of a record's spectrum stands LINE_FACTOR times above the spectrum's median (its noise floor) only where a
#   line is: white noise's bins are Rayleigh distributed, with the median 1.18 times the scale, and one exceeds ten
#   medians with probability exp(-69) (none of a million bins by chance);
LINE_FACTOR = 10.0
# - a harmonic's least-squares amplitude (or a mean) beyond LINE_SNR standard errors of the channel's noise is real:
#   noise alone reaches it with probability exp(-12.5) = 4e-6 (a mean: 6e-7);
LINE_SNR = 5.0
# - no accelerometer on the driven beam responds at the drive's lines with less than DEAD_LEVEL of another's: the
#   modes' shapes rise from the clamp as (x / L)^2, so only a sensor within about a millimetre of the clamp would;
#   a channel that far below its peers is flat but for noise or crosstalk;
DEAD_LEVEL = 1e-6
# - a declared excitation frequency is the drive's rounded or nominal value, a few per cent off at most: a record whose
#   lines sit further off is read as a wrong sampling rate (another acquisition rate, a resampled export); the
#   message names both fixes either way;
RATE_FACTOR_LIMIT = 0.05
# - a flat top is clipping where the signal's continuation (a quadratic through the samples either side of it) runs
#   beyond the held value by more than CLIP_EXCESS times the channel's sample-to-sample scatter (the same
#   continuation's robust residual at every sample: noise, quantisation and curvature together); a clean periodic
#   record's repeated peak, a sample the continuation meets within its scatter, is not;
CLIP_EXCESS = 5.0
# - the value at a clipped channel's limit collects every sample beyond it: it recurs CLIP_SPIKE times as often as the
#   values next to it, which no unclipped record's extreme does (``flat_tops``).
CLIP_SPIKE = 4.0
# - a piezoelectric transducer holds no mean, and a periodic motion's acceleration has none over whole periods: a mean
#   beyond LINE_SNR standard errors is an offset, worth a warning from OFFSET_SHARE of the channel's drive line
#   (or, in a random test, of its rms) on (a smaller one is harmless and common).
OFFSET_SHARE = 0.01


def channels_of(raw: xr.Dataset, path: str = "record") -> Iterator[tuple]:
    """Yield (name, samples) of the force and every accelerometer, after the magnitude check.

    Parameters
    ----------
    raw
        The raw record (``force`` over time [N], ``acceleration`` over sensor and time [m/s^2], the ``sensor``
        coordinate).
    path
        The record's file, for messages.

    Yields
    ------
    channel : tuple[str, np.ndarray]
        The channel's name ("force" first, then the sensors' names) and its samples [N] (the force) or [m/s^2] (an
        accelerometer), shape (n_samples,).

    Raises
    ------
    RawDataError
        Where a channel's magnitude passes ``PHYSICAL_LIMIT`` (a scaling error).
    """
    chans = [("force", np.asarray(raw["force"].values, float))]
    chans += [(str(s), a) for s, a in zip(raw["sensor"].values, np.asarray(raw["acceleration"].values, float))]
    for name, x in chans:
        big = float(np.max(np.abs(x))) if x.size else 0.0
        if big > PHYSICAL_LIMIT:
            raise RawDataError(
                f"{path}: channel {name}: magnitude check failed: |value| reaches {big:.3g} (N or m/s^2), "
                f"beyond any vibration test ({PHYSICAL_LIMIT:g}); check the channel's units and sensitivity"
            )
    yield from chans


def unit_of(k: int) -> str:
    """Return the unit of channel ``k`` of ``channels_of`` (the force first).

    Parameters
    ----------
    k
        The channel's index in ``channels_of`` (0: the force).

    Returns
    -------
    unit : str
        "N" for the force, "m/s^2" for an accelerometer.
    """
    return "N" if k == 0 else "m/s^2"


def dead_fix(k: int) -> str:
    """Return what a dead channel ``k`` of ``channels_of`` is and what to do.

    Parameters
    ----------
    k
        The channel's index in ``channels_of`` (0: the force).

    Returns
    -------
    text : str
        The likely cause and the fix, for a message.
    """
    if k == 0:
        return (
            "a dead force transducer, its cable or a channel not recorded; check the transducer and its cable "
            "(the identification needs the force)"
        )
    return (
        "a dead sensor, cable or a channel not recorded; check the sensor and its cable, or remove it from the "
        "record and from structure.sensors"
    )


def flat_channel_check(channels: Sequence[tuple[str, np.ndarray]], path: str) -> None:
    """Refuse a channel whose samples are all equal: nothing was recorded on it.

    No clipping, frequency or harmonic means anything there.

    Parameters
    ----------
    channels
        [(name, samples)] from ``channels_of``, the force first: samples [N] (the force) or [m/s^2] (an
        accelerometer), each of shape (n_samples,).
    path
        The record's file, for messages.

    Raises
    ------
    RawDataError
        For the first channel whose samples are all equal.
    """
    for k, (name, x) in enumerate(channels):
        if x.size and float(np.ptp(x)) == 0.0:
            raise RawDataError(
                f"{path}: channel {name}: dead-channel check failed: channel {name} is flat (all samples equal to "
                f"{x[0]:.6g} {unit_of(k)}): {dead_fix(k)}"
            )


def samples_at_limit(x: np.ndarray) -> int:
    """Return how many samples sit at the channel's largest or smallest value.

    Not all of them are clipped: a clean periodic record repeats its peak sample every period; ``flat_tops`` tells.

    Parameters
    ----------
    x
        The channel's samples [N] (the force) or [m/s^2] (an accelerometer), shape (n_samples,).

    Returns
    -------
    count : int
        The larger of the counts at the largest and at the smallest value (every sample for a flat channel).
    """
    span = float(np.ptp(x))
    if span == 0.0:
        return x.size
    tol = 1e-9 * span
    return int(max(np.sum(x >= x.max() - tol), np.sum(x <= x.min() + tol)))


_SIDE = 3  # samples either side of a flat top through which its continuation is drawn


def _continuation_scatter(x: np.ndarray, tol: float) -> float:
    """Return the channel's sample-to-sample scatter.

    The robust rms (1.4826 median absolute value) of each sample less the quadratic through the ``_SIDE`` samples either
    side of it, over the samples off its extreme values (within ``tol``: a clipped channel's flat tops, which the
    quadratic meets exactly, left out).
    """
    if x.size < 2 * _SIDE + 1:
        return 0.0
    u = np.r_[-_SIDE:0, 1 : _SIDE + 1].astype(float)
    kernel = np.zeros(2 * _SIDE + 1)
    kernel[u.astype(int) + _SIDE] = np.linalg.pinv(np.vander(u, 3, increasing=True))[0]  # the quadratic at u = 0
    centre = x[_SIDE:-_SIDE]
    residual = np.abs(centre - np.correlate(x, kernel, mode="valid"))
    off = (centre < x.max() - tol) & (centre > x.min() + tol)
    return 1.4826 * float(np.median(residual[off] if off.any() else residual))


def flat_tops(x: np.ndarray, unit: str = "") -> tuple[int, str]:
    """Return the clipping of one channel: how many samples are held at its largest or smallest value, and the evidence.

    A clipped channel holds samples at the range limit where the signal went on beyond it, seen two ways:

    - the limit's value collects every sample beyond it: it occurs more than ``CLIP_SPIKE`` times as often as each of
      the three values just below it (plus one). A record with noise repeats no value, a clean periodic record repeats
      each of its values once a period, the peak as often as its neighbours, and a quantised sine's top step holds at
      most about 2.4 times the samples of the step below it (its arcsine distribution);
    - a run at the limit (gaps of up to two samples below it bridged) that the signal's continuation, the quadratic
      through the ``_SIDE`` samples either side of it, exceeds by ``CLIP_EXCESS`` times the channel's
      sample-to-sample scatter: a flat top. A clean periodic record's peak, repeated at the same phase every period
      (one or two samples, the neighbours below), is met by that continuation within the scatter.

    Parameters
    ----------
    x
        The channel's samples [N] (the force) or [m/s^2] (an accelerometer), shape (n_samples,).
    unit
        The channel's unit, for the evidence's text ("" for none).

    Returns
    -------
    held : int
        How many samples are held at the limits in flat tops (0 for none).
    evidence : str
        What shows it, with values in ``unit`` ("" for none).
    """
    span = float(np.ptp(x))
    if span == 0.0 or x.size < 2 * _SIDE + 2:
        return 0, ""
    tol = 1e-9 * span  # values this close are one value (a periodic record's repeats differ by rounding)
    q = np.round((x - x.min()) / tol).astype(np.int64)
    counts = np.unique(q, return_counts=True)[1]
    scatter = None
    held, evidence = 0, ""
    for sign in (1.0, -1.0):
        y = sign * x
        limit = float(y.max())
        at = np.flatnonzero(q == (q.max() if sign > 0 else 0))
        if at.size < 2:
            continue
        inwards = counts[::-1] if sign > 0 else counts  # the values' counts from this limit inwards
        n_limit = at.size
        most = int(inwards[1:4].max()) if inwards.size > 1 else 0
        if n_limit > CLIP_SPIKE * (most + 1):
            side_held = n_limit
            side_evidence = (
                f"the limit's value occurs {n_limit} times, each of the three just below it at most {most} times"
            )
        else:
            if scatter is None:
                scatter = max(_continuation_scatter(x, tol), 1e-12 * span)
            side_held, worst = 0, 0.0
            for top in np.split(at, np.flatnonzero(np.diff(at) > 3) + 1):
                i, j = int(top[0]), int(top[-1])
                if i < _SIDE or j + _SIDE >= y.size:
                    continue  # at the record's edge: no continuation on one side
                u = np.r_[i - _SIDE : i, j + 1 : j + 1 + _SIDE]
                c = (i + j) / 2
                coef = np.polyfit(u - c, y[u], 2)
                excess = float(np.max(np.polyval(coef, np.arange(i, j + 1) - c))) - limit
                if excess > CLIP_EXCESS * scatter:
                    side_held += top.size
                    worst = max(worst, excess)
            side_evidence = (
                f"the signal's continuation runs up to {worst:.3g}{' ' + unit if unit else ''} beyond it, "
                f"{worst / scatter:.3g} times the channel's sample-to-sample scatter"
            )
        if side_held > held:
            evidence = side_evidence
        held += side_held
    return held, evidence


def clipping_warnings(
    channels: Sequence[tuple[str, np.ndarray]], path: str, clip_samples: int, drive: str
) -> list[str]:
    """Refuse a clipped channel; warn of one clipped half as much.

    A channel is refused when ``clip_samples`` samples are held at its range limit in flat tops (``flat_tops``), and
    warned of from half that many.

    Parameters
    ----------
    channels
        [(name, samples)] from ``channels_of``, the force first: samples [N] (the force) or [m/s^2] (an
        accelerometer), each of shape (n_samples,).
    path
        The record's file, for messages.
    clip_samples
        Samples held at the range limit that make a channel clipped (config ``raw_checks.clip_samples``).
    drive
        What to lower besides the input range's gain, for the message ("excitation", "force level").

    Returns
    -------
    warnings : list[str]
        One warning per channel with at least half of ``clip_samples`` (and two) samples held.

    Raises
    ------
    RawDataError
        For the first channel with ``clip_samples`` or more samples held.
    """
    warnings = []
    for k, (name, x) in enumerate(channels):
        held, evidence = flat_tops(x, unit_of(k))
        if held >= clip_samples:
            raise RawDataError(
                f"{path}: channel {name}: clipping check failed: {held} samples sit at the range limit "
                f"({x.max():.6g} / {x.min():.6g} {unit_of(k)}), held there ({evidence}); raw_checks.clip_samples = "
                f"{clip_samples}. Lower the input range's gain or the {drive} and record again"
            )
        if held >= max(2, clip_samples // 2):
            warnings.append(f"{name}: {held} samples held at the range limit (clipping check: {clip_samples})")
    return warnings


def _offset_text(k: int) -> str:
    """Return what an offset on channel ``k`` of ``channels_of`` (the force first) is and what to check."""
    what = "a transducer" if k == 0 else "an accelerometer"
    zero = "the charge amplifier's" if k == 0 else "the charge amplifier's or signal conditioner's"
    return f"{what} offset or drift (harmless to the identification, which uses the harmonics; check {zero} zero)"


def offset_warnings(
    names: Sequence[str], mean: np.ndarray, reference: np.ndarray, noise: np.ndarray, n: int, what: Sequence[str]
) -> list[str]:
    """Return warnings for channels whose mean is an offset worth a warning.

    A channel's ``mean`` is one where it stands ``LINE_SNR`` standard errors (``noise`` rms over ``n`` samples) out of
    zero and exceeds ``OFFSET_SHARE`` of ``reference`` (its drive line, or its rms).

    Parameters
    ----------
    names
        The channels' names, the force first (``channels_of``'s order).
    mean
        Each channel's mean [N] (the force) or [m/s^2] (an accelerometer), shape (n_channels,).
    reference
        What each mean is compared with, its drive line's amplitude or its rms [unit of mean], shape (n_channels,).
    noise
        Each channel's noise rms [unit of mean], shape (n_channels,).
    n
        The number of samples the means are taken over.
    what
        The name of each channel's reference, for the message ("amplitude at w", "rms").

    Returns
    -------
    warnings : list[str]
        One warning per channel with an offset.
    """
    out = []
    for k, name in enumerate(names):
        m = float(mean[k])
        if abs(m) > LINE_SNR * noise[k] / np.sqrt(n) and abs(m) > OFFSET_SHARE * reference[k]:
            out.append(
                f"{name}: mean {m:.3g} {unit_of(k)}, {abs(m) / reference[k]:.2g} of its {what[k]}: {_offset_text(k)}"
            )
    return out
