"""Checks of a dual-sine raw record before identification: its harmonic content at the
excitation frequency and its stationarity (first against last third of the record)."""

from __future__ import annotations

from typing import Mapping

import numpy as np
import xarray as xr

from .io import RawDataError
from .harmonics import harmonic_content


def driving_point_index(raw: xr.Dataset, excitation_position_m: float, path: str, tol_m: float = 1e-3) -> int:
    """Index of the accelerometer at the driving point d_p."""
    pos = np.asarray(raw["position"].values, dtype=float)
    i = int(np.argmin(np.abs(pos - excitation_position_m)))
    if abs(pos[i] - excitation_position_m) > tol_m:
        raise RawDataError(
            f"{path}: no accelerometer at the driving point d_p = {excitation_position_m} m "
            f"(positions {pos.tolist()} m); the response control and Table 2 refer to it"
        )
    return i


def dual_sine_check_dataset(raw: xr.Dataset, structure_cfg: Mapping, path: str, max_harmonic: int) -> xr.Dataset:
    """Harmonic amplitudes of every channel at h f0 (h = 1..max_harmonic), the driving-point
    A1 (at f0) and A2 (at 3 f0) of Table 2, and their change between the record's first and
    last thirds."""
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
        coords={"sensor": raw["sensor"].values, "harmonic": h, "excitation_harmonic": [1, 3]},
        attrs={
            "A1_m_per_s2": float(np.abs(c_acc[i, 0])),
            "A2_m_per_s2": float(np.abs(c_acc[i, 2])) if max_harmonic >= 3 else np.nan,
            "excitation_frequency_hz": f0,
            "periods": float(acc.shape[1] / fs * f0),
            "driving_point_sensor": str(raw["sensor"].values[i]),
        },
    )


# ------------------------------------------------------------------------------------------
# validation of raw records before identification (config raw_checks); a failure stops the
# record with a message naming the file, the channel, the check and the measured value; a value
# beyond half its limit is a warning stored in the check dataset and shown in the report
# ------------------------------------------------------------------------------------------


def check_settings(checks: Mapping | None) -> dict:
    """raw_checks with the schema's defaults filled in (max_harmonic and min_periods, the record reader's, apart)."""
    from .config import schema_defaults

    defaults = {k: v for k, v in schema_defaults("raw_checks").items() if k not in ("max_harmonic", "min_periods")}
    return {**defaults, **{k: v for k, v in dict(checks or {}).items() if v is not None}}


# no force (N) or acceleration (m/s^2) of a vibration test comes near this: a larger value is a scaling error
PHYSICAL_LIMIT = 1.0e9


def _channels(raw: xr.Dataset, path: str = "record"):
    """(name, samples) of the force and every accelerometer, after the magnitude check."""
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


def samples_at_limit(x: np.ndarray) -> int:
    """How many samples sit at the channel's largest or smallest value (a flat top: clipping)."""
    span = float(np.ptp(x))
    if span == 0.0:
        return x.size
    tol = 1e-9 * span
    return int(max(np.sum(x >= x.max() - tol), np.sum(x <= x.min() + tol)))


def clipping_warnings(channels, path: str, clip_samples: int, drive: str) -> list[str]:
    """Refuse a clipped channel of ``channels`` ([(name, samples)], from ``_channels``) when
    ``clip_samples`` samples sit at its extreme value; warn from half that many."""
    warnings = []
    for name, x in channels:
        at = samples_at_limit(x)
        if at >= clip_samples:
            raise RawDataError(
                f"{path}: channel {name}: clipping check failed: {at} samples sit at the range limit "
                f"({x.max():.6g} / {x.min():.6g}); raw_checks.clip_samples = {clip_samples}. "
                f"Lower the input range's gain or the {drive} and record again"
            )
        if at >= max(2, clip_samples // 2):
            warnings.append(f"{name}: {at} samples at the range limit (clipping check: {clip_samples})")
    return warnings


def recovered_frequency(x: np.ndarray, fs: float, declared_hz: float) -> tuple[float, int]:
    """The excitation frequency found in a record: the strongest spectral line of ``x`` (Hann
    window), refined by maximising the windowed DFT magnitude, divided by its harmonic number h of
    the declared frequency. Returns (frequency in Hz, h)."""
    from scipy.optimize import minimize_scalar

    n = x.size
    w = np.hanning(n)
    y = (x - x.mean()) * w
    spec = np.abs(np.fft.rfft(y))
    spec[0] = 0.0
    k = int(np.argmax(spec))
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
    h = max(1, int(round(res.x / declared_hz)))
    return float(res.x / h), h


def validate_dual_sine(raw: xr.Dataset, path: str, checks: Mapping) -> list[str]:
    """Clipping, excitation frequency and stationarity of a dual-sine record; raises RawDataError on
    the first failure, returns the warnings."""
    c = check_settings(checks)
    fs = float(raw.attrs["sampling_rate_hz"])
    f0 = float(raw.attrs["excitation_frequency_hz"])
    n = raw.sizes["time"]
    duration = n / fs
    channels = list(_channels(raw, path))
    warnings = clipping_warnings(channels, path, c["clip_samples"], "excitation")
    f_rec, h = recovered_frequency(np.asarray(raw["force"].values, float), fs, f0)
    drift_cycles = abs(f_rec - f0) * duration
    if h not in (1, 2, 3) or drift_cycles > c["frequency_tolerance_cycles"]:
        raise RawDataError(
            f"{path}: channel force: excitation frequency check failed: the record's excitation is at "
            f"{f_rec:.6g} Hz (strongest line at harmonic {h}), the file declares {f0:.6g} Hz, "
            f"{drift_cycles:.3g} cycles apart over the record (raw_checks.frequency_tolerance_cycles = "
            f"{c['frequency_tolerance_cycles']}); correct excitation_frequency_hz"
        )
    if drift_cycles > 0.5 * c["frequency_tolerance_cycles"]:
        warnings.append(
            f"force: excitation at {f_rec:.6g} Hz against {f0:.6g} Hz declared ({drift_cycles:.3g} cycles "
            "over the record)"
        )
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
    """Whether an amplitude's change over a record's thirds (``first``, ``middle``, ``last``) is a steady drift: both
    steps the same way and within a factor 2 of each other, as a slowly drifting preload gives (the rig's drifts of
    0.1-0.2: steps within 10 % of each other). A transient decays (its first step larger), an unsettled motion
    wanders."""
    d1, d2 = middle - first, last - middle
    if d1 * d2 <= 0.0:
        return False
    return min(abs(d1), abs(d2)) >= 0.5 * max(abs(d1), abs(d2))


def validate_random_test(raw: xr.Dataset, path: str, checks: Mapping, segment_length: int, blocks: int) -> list[str]:
    """Clipping, record length and frequency resolution of the random test (before the FRF)."""
    c = check_settings(checks)
    fs = float(raw.attrs["sampling_rate_hz"])
    n = raw.sizes["time"]
    warnings = clipping_warnings(list(_channels(raw, path)), path, c["clip_samples"], "force level")
    need = 2 * segment_length * blocks
    if n < need:
        raise RawDataError(
            f"{path}: record length check failed: {n} samples, fewer than 2 x frf.segment_length x "
            f"modal.uncertainty_blocks = {need}; record {need / fs:.1f} s or more, or lower "
            "frf.segment_length"
        )
    df = fs / segment_length
    if df > c["max_frf_resolution_hz"]:
        raise RawDataError(
            f"{path}: FRF resolution check failed: {fs:g} Hz / frf.segment_length {segment_length} = "
            f"{df:.3g} Hz between lines, coarser than raw_checks.max_frf_resolution_hz = "
            f"{c['max_frf_resolution_hz']}; raise frf.segment_length (and the record length)"
        )
    return warnings


def validate_coherence(frf: xr.Dataset, band_hz, path: str, checks: Mapping) -> tuple[dict, list[str]]:
    """Share of the FRF lines in ``band_hz`` whose coherence reaches raw_checks.min_coherence, per
    channel; raises RawDataError when a channel's share is below raw_checks.coherence_fraction."""
    c = check_settings(checks)
    f = frf["frequency"].values
    band = (f >= band_hz[0]) & (f <= band_hz[1])
    shares, warnings = {}, []
    for s, coh in zip(frf["sensor"].values, frf["coherence"].values):
        share = float(np.mean(coh[band] >= c["min_coherence"]))
        shares[str(s)] = share
        if share < c["coherence_fraction"]:
            raise RawDataError(
                f"{path}: channel {s}: coherence check failed: only {share:.1%} of the lines in "
                f"{band_hz[0]:g}-{band_hz[1]:g} Hz reach coherence {c['min_coherence']} "
                f"(raw_checks.coherence_fraction = {c['coherence_fraction']}); raise the force level, "
                "average longer, or check the sensor and its cable"
            )
        if share < 0.5 * (1.0 + c["coherence_fraction"]):
            warnings.append(f"{s}: {share:.1%} of the band's lines reach coherence {c['min_coherence']}")
    return shares, warnings


def validate_frf_resolution(frf: xr.Dataset, path: str, checks: Mapping) -> list[str]:
    """The spacing of an FRF's lines (Hz) against raw_checks.max_frf_resolution_hz, for FRFs given as such (an FRF
    file: no record length or segment to check); a spacing beyond half of the limit is a warning."""
    c = check_settings(checks)
    f = frf["frequency"].values
    df = float((f[-1] - f[0]) / (f.size - 1))
    if df > c["max_frf_resolution_hz"]:
        raise RawDataError(
            f"{path}: FRF resolution check failed: the lines are {df:.3g} Hz apart, coarser than "
            f"raw_checks.max_frf_resolution_hz = {c['max_frf_resolution_hz']}; measure the FRFs with a finer "
            "resolution (longer blocks, or zoom on modal.band_hz)"
        )
    if df > 0.5 * c["max_frf_resolution_hz"]:
        return [f"FRF lines {df:.3g} Hz apart (raw_checks.max_frf_resolution_hz = {c['max_frf_resolution_hz']})"]
    return []
