"""Checks of the random test before identification.

Its record (dead channels, clipping, offsets, the record's length and the FRF's resolution) and its FRF (the
coherence in the modal band, the lines' spacing, the driving point's sign), thresholds from the physics and
statistics of the records (the constants of ``raw_checks``) or from the config's raw_checks.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from .io import RawDataError
from .raw_checks import (
    DEAD_LEVEL,
    channels_of,
    check_settings,
    clipping_warnings,
    dead_fix,
    flat_channel_check,
    offset_warnings,
)


def validate_random_test(raw: xr.Dataset, path: str, checks: Mapping, segment_length: int, blocks: int) -> list[str]:
    """Check the random test's record: dead channels, clipping, offsets, record length and frequency resolution.

    Run before the FRF; a sensor that records noise alone is refused by the coherence check after it
    (``validate_coherence``). A flat or clipped channel is refused by ``raw_checks``' checks, with a
    ``RawDataError``.

    Parameters
    ----------
    raw
        The random test's record (``io.read_raw``): ``force`` [N] and ``acceleration`` [m/s^2] over ``time``, the
        attribute ``sampling_rate_hz``.
    path
        The record's file, named in the messages.
    checks
        The config's ``raw_checks`` block (``clip_samples``, ``max_frf_resolution_hz`` read; the schema's defaults
        where left out).
    segment_length
        Samples per FRF segment (frf.segment_length).
    blocks
        Sub-records the modal fit's uncertainty needs (modal.uncertainty_blocks).

    Returns
    -------
    warnings : list[str]
        Messages on nearly clipped channels and channels with an offset.

    Raises
    ------
    RawDataError
        When an accelerometer is dead (its rms below ``raw_checks.DEAD_LEVEL`` of the strongest one's), the record
        holds fewer than 2 x segment_length x blocks samples, or the FRF's lines would be further apart than
        raw_checks.max_frf_resolution_hz.
    """
    c = check_settings(checks)
    fs = float(raw.attrs["sampling_rate_hz"])
    n = raw.sizes["time"]
    channels = list(channels_of(raw, path))
    flat_channel_check(channels, path)
    warnings = clipping_warnings(channels, path, c["clip_samples"], "force level")
    names = [name for name, _ in channels]
    rms = np.array([float(np.std(x)) for _, x in channels])
    if rms.size > 1:
        top = 1 + int(np.argmax(rms[1:]))
        for k in range(1, rms.size):
            if rms[k] < DEAD_LEVEL * rms[top]:
                raise RawDataError(
                    f"{path}: channel {names[k]}: dead-channel check failed: channel {names[k]} is flat but for "
                    f"noise: its rms response, {rms[k]:.3g} m/s^2, is {rms[k] / rms[top]:.2g} of the strongest "
                    f"accelerometer's ({names[top]}, {rms[top]:.3g} m/s^2), and no accelerometer on the driven beam "
                    f"responds with less than {DEAD_LEVEL:g} of another's: {dead_fix(k)}"
                )
    mean = np.array([float(np.mean(x)) for _, x in channels])
    warnings += offset_warnings(names, mean, rms, rms, n, ["rms"] * len(names))
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


def driving_point_sign_warnings(frf: xr.Dataset, excitation_position_m: float, band_hz: Sequence[float]) -> list[str]:
    """Warn where the driving point's accelerance has the sign of a flipped force or accelerometer.

    The driving point's accelerance is positive-imaginary at its resonances for any passive structure (its residues
    are phi_d^2 > 0: H = i phi_d^2 / (2 zeta) at resonance). Negative there, at most of its strongest peaks (up to
    three) in ``band_hz``, the force's or the driving-point accelerometer's sign is flipped: a warning (the linear
    chain reads the modes' magnitudes and is not affected; the same channels of the dual-sine records are worth
    checking). No sensor at the driving point (within 1 mm): nothing to say.

    Parameters
    ----------
    frf
        The FRF dataset (results/linear/frf.nc): ``h1_real``, ``h1_imag`` [m/s^2/N] over (``sensor``,
        ``frequency`` [Hz]), the coordinate ``position`` [m] of each sensor.
    excitation_position_m
        Position of the driving point along the beam [m].
    band_hz
        The modal band (modal.band_hz): lowest and highest frequency [Hz].

    Returns
    -------
    warnings : list[str]
        One message where the sign looks flipped, else none.
    """
    pos = np.asarray(frf["position"].values, float) if "position" in frf.coords else np.array([])
    if pos.size == 0 or np.min(np.abs(pos - excitation_position_m)) > 1e-3:
        return []
    d = int(np.argmin(np.abs(pos - excitation_position_m)))
    f = frf["frequency"].values
    h = frf["h1_real"].values[d] + 1j * frf["h1_imag"].values[d]
    idx = np.where((f >= band_hz[0]) & (f <= band_hz[1]))[0]
    if idx.size < 3:
        return []
    mag = np.abs(h)
    peaks = [i for i in idx[1:-1] if mag[i] > mag[i - 1] and mag[i] >= mag[i + 1] and mag[i] > 0.05 * mag[idx].max()]
    peaks = sorted(sorted(peaks, key=lambda i: -mag[i])[:3])
    negative = [i for i in peaks if h[i].imag < 0]
    if not peaks or 2 * len(negative) <= len(peaks):
        return []
    at = ", ".join(f"{f[i]:.4g} Hz" for i in negative)
    return [
        f"{frf['sensor'].values[d]} (driving point): the accelerance's imaginary part is negative at the resonances "
        f"{at}, where a passive structure's is positive: the force's or this accelerometer's sign is flipped; the "
        "linear chain reads the modes' magnitudes and is not affected, but check the same channels' signs in the "
        "dual-sine records"
    ]


def validate_coherence(frf: xr.Dataset, band_hz: Sequence[float], path: str, checks: Mapping) -> tuple[dict, list[str]]:
    """Return the share of the FRF lines in the band whose coherence reaches raw_checks.min_coherence, per channel.

    Parameters
    ----------
    frf
        The FRF dataset (results/linear/frf.nc): ``coherence`` over (``sensor``, ``frequency`` [Hz]).
    band_hz
        The modal band (modal.band_hz): lowest and highest frequency [Hz].
    path
        The file the FRFs come from, named in the messages.
    checks
        The config's ``raw_checks`` block (``min_coherence``, ``coherence_fraction`` read; the schema's defaults
        where left out).

    Returns
    -------
    shares : dict
        {sensor: share of the band's lines whose coherence reaches raw_checks.min_coherence} (fractions in [0, 1]).
    warnings : list[str]
        Messages on the channels whose share lies below halfway from raw_checks.coherence_fraction to 1.

    Raises
    ------
    RawDataError
        When a channel's share is below raw_checks.coherence_fraction.
    """
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
    """Check the spacing of an FRF's lines against raw_checks.max_frf_resolution_hz.

    For FRFs given as such (an FRF file: no record length or segment to check); a spacing beyond half of the limit
    is a warning.

    Parameters
    ----------
    frf
        The FRF dataset (results/linear/frf.nc) over evenly spaced ``frequency`` lines [Hz].
    path
        The file the FRFs come from, named in the messages.
    checks
        The config's ``raw_checks`` block (``max_frf_resolution_hz`` read; the schema's default where left out).

    Returns
    -------
    warnings : list[str]
        One message where the lines lie more than half the limit apart, else none.

    Raises
    ------
    RawDataError
        When the lines lie further apart than raw_checks.max_frf_resolution_hz.
    """
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
