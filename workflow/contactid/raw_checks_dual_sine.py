"""Checks of a dual-sine record before identification.

Its harmonic content at the excitation frequency and its stationarity (first against last third of the record), its
validation (dead channels, clipping, the sampling rate and excitation frequency, offsets, stationarity) and its level
against the random test's FRF, each check a small function of the record's numbers whose thresholds follow from the
physics and statistics of the records (the constants of ``raw_checks``) or from the config's raw_checks.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from .harmonics import harmonic_amplitudes, harmonic_content, synthesize
from .io import RawDataError
from .raw_checks import (
    DEAD_LEVEL,
    LINE_FACTOR,
    LINE_SNR,
    RATE_FACTOR_LIMIT,
    channels_of,
    check_settings,
    clipping_warnings,
    dead_fix,
    flat_channel_check,
    offset_warnings,
    unit_of,
)


def driving_point_index(raw: xr.Dataset, excitation_position_m: float, path: str, tol_m: float = 1e-3) -> int:
    """Return the index of the accelerometer at the driving point d_p.

    Parameters
    ----------
    raw
        A raw record: reads its coordinate ``position`` (sensor) [m].
    excitation_position_m
        The driving point's distance from the clamp [m] (config ``structure.excitation_position_m``).
    path
        The record's path, for the message.
    tol_m
        How far the nearest accelerometer may lie from the driving point [m].

    Returns
    -------
    index : int
        The accelerometer's index along the record's sensor dimension.

    Raises
    ------
    RawDataError
        When no accelerometer lies within ``tol_m`` of the driving point.
    """
    pos = np.asarray(raw["position"].values, dtype=float)
    i = int(np.argmin(np.abs(pos - excitation_position_m)))
    if abs(pos[i] - excitation_position_m) > tol_m:
        raise RawDataError(
            f"{path}: no accelerometer at the driving point d_p = {excitation_position_m} m "
            f"(positions {pos.tolist()} m); the response control and Table 2 refer to it"
        )
    return i


def dual_sine_check_dataset(raw: xr.Dataset, structure_cfg: Mapping, path: str, max_harmonic: int) -> xr.Dataset:
    """Return the harmonic amplitudes of every channel and the driving point's A1 and A2 with their change.

    Harmonic amplitudes and phases of every channel at h f0 (h = 1..max_harmonic), the driving-point A1 (at f0) and
    A2 (at 3 f0) of Table 2, and their change between the record's first and last thirds.

    Parameters
    ----------
    raw
        The dual-sine record: ``force`` (time) [N], ``acceleration`` (sensor, time) [m/s^2], the coordinates
        ``sensor`` and ``position`` [m], the attributes ``sampling_rate_hz`` and ``excitation_frequency_hz`` [Hz].
    structure_cfg
        The config's ``structure`` block: reads ``excitation_position_m`` [m].
    path
        The record's path, for messages.
    max_harmonic
        The highest harmonic of f0 (config ``raw_checks.max_harmonic``).

    Returns
    -------
    check : xr.Dataset
        The amplitudes (m/s^2, N), phases (rad) and stationarity change (1), with the attributes A1_m_per_s2,
        A2_m_per_s2 (NaN below three harmonics), the excitation frequency, the number of periods and the
        driving-point sensor.
    """
    fs = float(raw.attrs["sampling_rate_hz"])
    f0 = float(raw.attrs["excitation_frequency_hz"])
    h = np.arange(1, max_harmonic + 1)
    acc = raw["acceleration"].values
    c_acc = np.array([harmonic_content(a, fs, f0, h) for a in acc])
    c_force = harmonic_content(raw["force"].values, fs, f0, h)
    i = driving_point_index(raw, float(structure_cfg["excitation_position_m"]), path)
    n = acc.shape[1] // 3
    first = np.abs(harmonic_content(acc[i, :n], fs, f0, (1, 3)))
    last = np.abs(harmonic_content(acc[i, -n:], fs, f0, (1, 3)))
    return xr.Dataset(
        {
            "acceleration_amplitude": (
                ("sensor", "harmonic"),
                np.abs(c_acc),
                {"units": "m/s^2", "long_name": "harmonic amplitude"},
            ),
            "acceleration_phase": (
                ("sensor", "harmonic"),
                np.angle(c_acc),
                {"units": "rad", "long_name": "harmonic phase (sine reference)"},
            ),
            "force_amplitude": ("harmonic", np.abs(c_force), {"units": "N", "long_name": "force harmonic amplitude"}),
            "force_phase": ("harmonic", np.angle(c_force), {"units": "rad", "long_name": "force harmonic phase"}),
            "stationarity_change": (
                "excitation_harmonic",
                np.abs(last / first - 1),
                {"units": "1", "long_name": "driving-point harmonic change, last vs first third"},
            ),
        },
        coords={
            "sensor": raw["sensor"].values,
            "position": (
                "sensor",
                np.asarray(raw["position"].values, float),
                {"units": "m", "long_name": "distance from the clamp"},
            ),
            "harmonic": h,
            "excitation_harmonic": [1, 3],
        },
        attrs={
            "A1_m_per_s2": float(np.abs(c_acc[i, 0])),
            "A2_m_per_s2": float(np.abs(c_acc[i, 2])) if max_harmonic >= 3 else np.nan,
            "excitation_frequency_hz": f0,
            "periods": float(acc.shape[1] / fs * f0),
            "driving_point_sensor": str(raw["sensor"].values[i]),
        },
    )


def _spectrum(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the Hann-windowed, mean-free record and its DFT magnitude (no DC bin)."""
    y = (x - x.mean()) * np.hanning(x.size)
    spec = np.abs(np.fft.rfft(y))
    spec[0] = 0.0
    return y, spec


def _refine(y: np.ndarray, fs: float, k: int) -> float:
    """Return the frequency (Hz) near bin ``k`` at which the windowed record ``y``'s DFT magnitude peaks."""
    from scipy.optimize import minimize_scalar

    n = y.size
    t = np.arange(n) / fs
    df = fs / n

    def neg_mag(f):
        return -abs(np.dot(y, np.exp(-2j * np.pi * f * t)))

    res = minimize_scalar(
        neg_mag,
        bounds=(max((k - 1) * df, 0.0), (k + 1) * df),
        method="bounded",
        options={"xatol": 1e-7 * max(k, 1) * df},
    )
    return float(res.x)


def _line_at(spec: np.ndarray, bin_: float, floor: float) -> float:
    """Return the magnitude of the line at (fractional) bin ``bin_`` of ``spec``, 0 where there is none.

    The largest bin within one of it where it stands ``LINE_FACTOR`` times above ``floor`` and twice above the bins
    three away on both sides (a line's main lobe, not another line's leakage, which falls off steadily); else 0.
    """
    j0 = int(round(bin_))
    if j0 < 1 or j0 + 1 >= spec.size:
        return 0.0
    j = j0 - 1 + int(np.argmax(spec[j0 - 1 : j0 + 2]))
    around = max(spec[j - 3] if j >= 3 else 0.0, spec[j + 3] if j + 3 < spec.size else 0.0)
    return float(spec[j]) if spec[j] >= LINE_FACTOR * floor and spec[j] >= 2.0 * around else 0.0


def excitation_lines(x: np.ndarray, fs: float, declared_hz: float) -> dict:
    """Return the dual-sine excitation a force record shows.

    Its strongest spectral line (Hann window, refined by maximising the windowed DFT magnitude) and whether it is the
    record's w or 3 w, by the line standing out at three times it or at a third of it (the stronger of the two where
    both do). With no partner line the strongest is taken as the 3 w of the declared frequency when within
    ``RATE_FACTOR_LIMIT`` of it, else as w.

    Parameters
    ----------
    x
        The force record [N], shape (n_t,): n_t samples.
    fs
        Sampling rate [Hz].
    declared_hz
        The declared excitation frequency w [Hz].

    Returns
    -------
    lines : dict
        ``frequency_hz`` (the record's w, in Hz), ``harmonic`` (1 or 3: the strongest line's), ``strongest_hz`` (the
        strongest line's frequency, in Hz), ``paired`` (the other line found) and ``line_to_floor`` (the strongest
        bin against the spectrum's median; inf where the median is 0).
    """
    y, spec = _spectrum(x)
    df = fs / x.size
    floor = float(np.median(spec[1:])) if spec.size > 1 else 0.0
    k = int(np.argmax(spec))
    f_a = _refine(y, fs, k)
    above, below = _line_at(spec, 3 * f_a / df, floor), _line_at(spec, f_a / 3 / df, floor)
    if below > 0.0 and below >= above:
        h = 3
    elif above > 0.0:
        h = 1
    else:
        h = 3 if abs(f_a / (3 * declared_hz) - 1.0) <= RATE_FACTOR_LIMIT else 1
    return {
        "frequency_hz": f_a / h,
        "harmonic": h,
        "strongest_hz": f_a,
        "paired": bool(above > 0.0 or below > 0.0),
        "line_to_floor": float(spec[k] / floor) if floor > 0.0 else np.inf,
    }


def recovered_frequency(x: np.ndarray, fs: float, declared_hz: float) -> tuple[float, int]:
    """Return the excitation frequency found in a dual-sine record (``excitation_lines``).

    Parameters
    ----------
    x
        The force record [N], shape (n_t,): n_t samples.
    fs
        Sampling rate [Hz].
    declared_hz
        The declared excitation frequency [Hz].

    Returns
    -------
    frequency : float
        The record's excitation frequency w [Hz].
    harmonic : int
        The harmonic number, 1 or 3, of the record's strongest line.
    """
    lines = excitation_lines(x, fs, declared_hz)
    return float(lines["frequency_hz"]), int(lines["harmonic"])


def excitation_frequency_check(force: np.ndarray, fs: float, f0: float, path: str, tolerance_cycles: float) -> list:
    """Refuse a force record whose excitation is not the declared one; warn from half the tolerance.

    Refused: a force record with no excitation line, one whose lines sit at r f0 and 3 r f0 (a wrong sampling rate
    or excitation frequency), or one whose excitation drifts more than ``tolerance_cycles`` cycles from the declared
    ``f0`` over the record.

    Parameters
    ----------
    force
        The force record [N], shape (n_t,): n_t samples.
    fs
        Sampling rate [Hz].
    f0
        The declared excitation frequency [Hz].
    path
        The record's path, for messages.
    tolerance_cycles
        How many cycles the excitation may drift from f0 over the record [cycles] (config
        ``raw_checks.frequency_tolerance_cycles``).

    Returns
    -------
    warnings : list
        One warning (str) where the drift exceeds half the tolerance; empty otherwise.

    Raises
    ------
    RawDataError
        When the force shows no line, its lines are off by a factor beyond ``RATE_FACTOR_LIMIT``, or it drifts more
        than the tolerance.
    """
    lines = excitation_lines(force, fs, f0)
    if lines["line_to_floor"] < LINE_FACTOR:
        raise RawDataError(
            f"{path}: channel force: excitation check failed: the force shows no spectral line (its strongest bin is "
            f"{lines['line_to_floor']:.3g} times the spectrum's median, a line stands {LINE_FACTOR:g} times above "
            "it): a dead force transducer, its cable, or a drive that was off; check the transducer, its cable and "
            "the shaker's amplifier"
        )
    f_rec, h = lines["frequency_hz"], lines["harmonic"]
    r = f_rec / f0
    if abs(r - 1.0) > RATE_FACTOR_LIMIT:
        if lines["paired"]:
            seen = f"the record's lines are at {f_rec:.6g} and {3 * f_rec:.6g} Hz"
        else:
            seen = (
                f"the record's one line is at {lines['strongest_hz']:.6g} Hz (taken as its {'3 w' if h == 3 else 'w'})"
            )
        raise RawDataError(
            f"{path}: channel force: sampling rate check failed: {seen}, {r:.4g} times the declared "
            f"excitation_frequency_hz = {f0:g} Hz and 3 f0 = {3 * f0:g} Hz: sampling_rate_hz ({fs:g}) is likely "
            f"{r:.4g} times the true rate ({fs / r:.5g} Hz), or excitation_frequency_hz {1 / r:.4g} times the true "
            f"one ({f_rec:.6g} Hz); correct the one that is wrong"
        )
    drift_cycles = abs(f_rec - f0) * force.size / fs
    if drift_cycles > tolerance_cycles:
        raise RawDataError(
            f"{path}: channel force: excitation frequency check failed: the record's excitation is at "
            f"{f_rec:.6g} Hz (strongest line at harmonic {h}), the file declares {f0:.6g} Hz, "
            f"{drift_cycles:.3g} cycles apart over the record (raw_checks.frequency_tolerance_cycles = "
            f"{tolerance_cycles}); correct excitation_frequency_hz"
        )
    if drift_cycles > 0.5 * tolerance_cycles:
        return [
            f"force: excitation at {f_rec:.6g} Hz against {f0:.6g} Hz declared ({drift_cycles:.3g} cycles "
            "over the record)"
        ]
    return []


def drive_lines(x: np.ndarray, fs: float, f0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return each channel's amplitudes at w and 3 w, its mean and its noise.

    The mean and the harmonics of f0 below 0.45 fs (the first 50 at most, at least 3) are fitted together by least
    squares over the whole record (partial periods included); the noise is the rms of what they leave.

    Parameters
    ----------
    x
        The channels' records, shape (k, n_t): k channels of n_t samples (a single record of shape (n_t,) is taken
        as one row); in ``validate_dual_sine`` the force [N] first, then the accelerometers [m/s^2].
    fs
        Sampling rate [Hz].
    f0
        Excitation frequency w / 2 pi [Hz].

    Returns
    -------
    lines : np.ndarray
        Each row's amplitudes at w and 3 w [unit of x], shape (k, 2).
    mean : np.ndarray
        Each row's mean [unit of x], shape (k,).
    noise : np.ndarray
        Each row's noise, rms [unit of x], shape (k,).
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[1]
    t = np.arange(n) / fs
    H = max(3, min(50, int(0.45 * fs / f0)))
    c = harmonic_amplitudes(x.T, t, 2 * np.pi * f0, range(1, H + 1)).T  # (k, H)
    periodic = synthesize(c, f0, t)
    mean = np.mean(x - periodic, axis=1)
    left = x - periodic - mean[:, None]
    noise = np.sqrt(np.sum(left**2, axis=1) / max(n - 2 * H - 1, 1))
    return np.abs(c[:, [0, 2]]), mean, noise


def dead_channel_check(names: Sequence[str], lines: np.ndarray, noise: np.ndarray, n: int, path: str) -> None:
    """Refuse a channel that records no response at the drive's lines.

    Refused: an accelerometer whose larger line (w or 3 w) is below ``DEAD_LEVEL`` of the strongest accelerometer's,
    or any channel whose lines do not stand ``LINE_SNR`` standard errors out of its own noise.

    Parameters
    ----------
    names
        The channels' names, the force first (``raw_checks.channels_of``), k of them.
    lines
        Each channel's amplitudes at w and 3 w (``drive_lines``), shape (k, 2): [N] in the force's row, [m/s^2] in
        the accelerometers'.
    noise
        Each channel's noise, rms (``drive_lines``), shape (k,): [N] for the force, [m/s^2] for an accelerometer.
    n
        Number of samples of the record.
    path
        The record's path, for messages.

    Raises
    ------
    RawDataError
        When an accelerometer is dead against the others, or a channel's lines do not stand out of its noise.
    """
    level = lines.max(axis=1)
    acc = level[1:]
    top = 1 + int(np.argmax(acc)) if acc.size else 0
    for k, name in enumerate(names):
        if k > 0 and level[k] < DEAD_LEVEL * level[top]:
            raise RawDataError(
                f"{path}: channel {name}: dead-channel check failed: channel {name} is flat but for noise "
                f"({noise[k]:.3g} m/s^2 rms): its response at w and 3 w, {level[k]:.3g} m/s^2, is "
                f"{level[k] / level[top]:.2g} of the strongest accelerometer's ({names[top]}, {level[top]:.3g} "
                f"m/s^2), and no accelerometer on the driven beam responds with less than {DEAD_LEVEL:g} of "
                f"another's: {dead_fix(k)}"
            )
        se = noise[k] * np.sqrt(2.0 / n)
        if level[k] < LINE_SNR * se:
            raise RawDataError(
                f"{path}: channel {name}: dead-channel check failed: its lines at w and 3 w ({level[k]:.3g} "
                f"{unit_of(k)}) do not stand out of its noise ({noise[k]:.3g} {unit_of(k)} rms, {LINE_SNR:g} standard "
                f"errors of a line: {LINE_SNR * se:.3g} {unit_of(k)}): it records noise, not the test: {dead_fix(k)}"
            )


def validate_dual_sine(raw: xr.Dataset, path: str, checks: Mapping) -> list[str]:
    """Validate a dual-sine record: dead channels, clipping, rates, offsets and stationarity.

    The checks: the channels' magnitude and flatness, clipping, the sampling rate and excitation frequency
    (``excitation_frequency_check``), dead channels, offsets, and stationarity: the amplitudes at w and 3 w in the
    record's first and last thirds, a change beyond the tolerance kept (with a warning) only where it is a steady
    drift (``steady_drift``) within the drift tolerance.

    Parameters
    ----------
    raw
        The dual-sine record: ``force`` (time) [N], ``acceleration`` (sensor, time) [m/s^2], the attributes
        ``sampling_rate_hz`` and ``excitation_frequency_hz`` [Hz].
    path
        The record's path, for messages.
    checks
        The config's ``raw_checks`` block (missing keys take the schema's defaults): reads ``clip_samples``,
        ``frequency_tolerance_cycles``, ``stationarity_tolerance`` and ``drift_tolerance``.

    Returns
    -------
    warnings : list[str]
        The warnings.

    Raises
    ------
    RawDataError
        On the first failed check (here: a change beyond the stationarity tolerance that is not a steady drift, or a
        drift beyond the drift tolerance; the other checks raise it themselves).
    """
    c = check_settings(checks)
    fs = float(raw.attrs["sampling_rate_hz"])
    f0 = float(raw.attrs["excitation_frequency_hz"])
    n = raw.sizes["time"]
    channels = list(channels_of(raw, path))
    flat_channel_check(channels, path)
    warnings = clipping_warnings(channels, path, c["clip_samples"], "excitation")
    warnings += excitation_frequency_check(channels[0][1], fs, f0, path, c["frequency_tolerance_cycles"])
    names = [name for name, _ in channels]
    lines, mean, noise = drive_lines(np.array([x for _, x in channels]), fs, f0)
    dead_channel_check(names, lines, noise, n, path)
    which = ["amplitude at " + ("w" if a >= b else "3 w") for a, b in lines]
    warnings += offset_warnings(names, mean, lines.max(axis=1), noise, n, which)
    third = n // 3
    for name, x in channels:
        whole = np.abs(harmonic_content(x, fs, f0, (1, 3)))
        first, middle, last = (
            np.abs(harmonic_content(x[k * third : (k + 1) * third], fs, f0, (1, 3))) for k in range(3)
        )
        scale = np.maximum(whole, 0.05 * whole.max())
        change = np.abs(last - first) / scale
        worst = int(np.argmax(change))
        if change[worst] > c["stationarity_tolerance"]:
            failed = (
                f"{path}: channel {name}: stationarity check failed: the amplitude at {(1, 3)[worst]} w "
                f"changes by {change[worst]:.3g} between the record's first and last thirds "
            )
            if not steady_drift(first[worst], middle[worst], last[worst]):
                raise RawDataError(
                    failed + f"(raw_checks.stationarity_tolerance = {c['stationarity_tolerance']}), not as a steady "
                    "drift (its change from the first third to the middle one and on to the last differ more than "
                    "twofold, as a transient's or an unsettled motion's do); record after the transient has died out, "
                    "or raise the tolerance"
                )
            if change[worst] > c["drift_tolerance"]:
                raise RawDataError(
                    failed + f"steadily, beyond raw_checks.drift_tolerance = {c['drift_tolerance']}; record a shorter "
                    "test, or raise the tolerance to diagnose the drift (the gap diagnosis can model a drifting "
                    "preload)"
                )
            warnings.append(
                f"{name}: amplitude at {(1, 3)[worst]} w drifts steadily by {change[worst]:.3g} over the record "
                f"(above raw_checks.stationarity_tolerance = {c['stationarity_tolerance']}): kept for the gap "
                "diagnosis, which can model a drifting preload"
            )
        elif change[worst] > 0.5 * c["stationarity_tolerance"]:
            warnings.append(f"{name}: amplitude at {(1, 3)[worst]} w changes by {change[worst]:.3g} over the record")
    return warnings


def steady_drift(first: float, middle: float, last: float) -> bool:
    """Judge whether an amplitude's change over a record's thirds is a steady drift.

    Steady: both steps the same way and within a factor 2 of each other, as a slowly drifting preload gives (the
    rig's drifts of 0.1-0.2: steps within 10 % of each other). A transient decays (its first step larger), an
    unsettled motion wanders.

    Parameters
    ----------
    first
        The amplitude over the record's first third [N] for the force, [m/s^2] for an accelerometer.
    middle
        The amplitude over its middle third [unit of first].
    last
        The amplitude over its last third [unit of first].

    Returns
    -------
    steady : bool
        Whether the change is a steady drift.
    """
    d1, d2 = middle - first, last - middle
    if d1 * d2 <= 0.0:
        return False
    return min(abs(d1), abs(d2)) >= 0.5 * max(abs(d1), abs(d2))


# a dual-sine record's accelerance at its drive (every sensor, at w and 3 w; the median of their magnitudes) lies
# within this factor of the random test's FRF at the same frequencies for any contact state: slip and separation
# move a resonance and damp it, which changes the accelerance near it a few times (0.3 and 2.5 on the other
# simulator's records), not fifty; beyond it the record is in other units than its label (mm/s^2: 1000) and its
# identification would overflow
LEVEL_FACTOR_LIMIT = 50.0


def _units_cause(factor: float) -> str:
    """Return what a record ``factor`` times off its expected level most likely has (``units_factors``)."""
    from .units_factors import units_error

    hit = units_error(factor, 0.3)  # the level against the stuck FRF scatters by the contact's state
    what = f"likely {hit[1]} (a factor {hit[0]:.4g})" if hit else "other units than the labels"
    return f"{what}, or a wrong sensitivity"


def frf_level_check(check: xr.Dataset, frf: xr.Dataset, path: str) -> float:
    """Refuse a dual-sine record whose accelerance at the drive is far off the random test's FRF; return the factor.

    Refused where it is more than ``LEVEL_FACTOR_LIMIT`` times off (either way).

    Parameters
    ----------
    check
        The record's ``dual_sine_check_dataset``.
    frf
        The random test's FRF dataset (results/linear/frf.nc).
    path
        The record's path, for the message.

    Returns
    -------
    factor : float
        The record's accelerance over the FRF's [-]: the median (taken on the logs) over the sensors both files
        hold (matched by position within 1 mm) and harmonics 1 and 3; NaN where they share no sensor or the FRF
        covers neither f0 nor 3 f0.

    Raises
    ------
    RawDataError
        When the factor is beyond ``LEVEL_FACTOR_LIMIT`` either way.
    """
    f0 = float(check.attrs["excitation_frequency_hz"])
    f = frf["frequency"].values
    h = frf["h1_real"].values + 1j * frf["h1_imag"].values
    pos_frf = np.asarray(frf["position"].values, float) if "position" in frf.coords else np.array([])
    pos_rec = np.asarray(check["position"].values, float) if "position" in check.coords else np.array([])
    ratios = []
    for j, x in enumerate(pos_rec):
        if pos_frf.size == 0 or np.min(np.abs(pos_frf - x)) > 1e-3:
            continue
        s = int(np.argmin(np.abs(pos_frf - x)))
        for k in (0, 2):
            if k >= check.sizes["harmonic"] or not f[0] <= (k + 1) * f0 <= f[-1]:
                continue
            force = float(check["force_amplitude"].values[k])
            model = abs(np.interp((k + 1) * f0, f, h[s].real) + 1j * np.interp((k + 1) * f0, f, h[s].imag))
            if force > 0 and model > 0:
                ratios.append(float(check["acceleration_amplitude"].values[j, k]) / force / model)
    if not ratios:
        return float("nan")
    factor = float(np.exp(np.median(np.log(np.maximum(ratios, 1e-300)))))
    if max(factor, 1.0 / factor) > LEVEL_FACTOR_LIMIT:
        raise RawDataError(
            f"{path}: level check failed: the record's accelerations over its force at the drive are {factor:.3g} "
            f"times the random test's FRF at the same frequencies (the median over sensors at w and 3 w), beyond the "
            f"factor {LEVEL_FACTOR_LIMIT:g} any contact state stays within: {_units_cause(factor)}; correct the "
            "record or its channel map"
        )
    return factor
