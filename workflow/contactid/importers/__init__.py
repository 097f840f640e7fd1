"""Importers: measured records in the files test rigs write, converted to the raw netCDF format.

``import_record(block, where, dual_sine)`` reads a configured import (UFF58, TDMS, or CSV with a
sidecar YAML), applies the explicit unit conversions of the channel map, and returns the raw
dataset of ``contactid.io``; ``export`` writes raw records in those formats (tests, round trips).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping

import numpy as np
import xarray as xr
import yaml

from ..io import RawDataError, raw_dataset
from .channels import FORMATS, ImportSpec, import_spec
from .readers import read_channels

__all__ = ["FORMATS", "ImportSpec", "import_record", "record_spec", "sidecar_path"]

# relative agreement of the sampling rates the file and the map state; a universal file writes the
# abscissa increment in its ASCII header with 6 significant digits (E13.5), so 1/5120 s reads back as 5119.987 Hz
RATE_TOLERANCE = {"uff58": 1e-5, "tdms": 1e-9, "csv": 1e-6}


def sidecar_path(file: str, sidecar: str | None = None) -> str:
    """Return the path of a CSV's sidecar YAML: as given, else the CSV's path with the suffix .yaml.

    Parameters
    ----------
    file
        Path of the CSV file.
    sidecar
        Path of its sidecar as configured, or None.

    Returns
    -------
    path : str
        The sidecar's path.
    """
    return sidecar or str(Path(file).with_suffix(".yaml"))


def record_spec(block: Mapping, where: str) -> ImportSpec:
    """Return the import of a configured record (a load case or the random test with ``format`` other than netcdf).

    The channel map comes from the config block, or from the sidecar for CSV (whose ``sampling_rate_hz`` and
    ``excitation_frequency_hz`` the config block may state instead).

    Parameters
    ----------
    block
        The record's config block (a load case of ``load_cases`` or ``random_test``): ``format``, ``file``,
        ``sidecar`` and ``channels``, ``sampling_rate_hz`` and ``excitation_frequency_hz`` are read.
    where
        The block's place in the config, for the messages (e.g. "load_cases.lc1").

    Returns
    -------
    spec : ImportSpec
        The parsed channel map with the file, its format and the rates.

    Raises
    ------
    RawDataError
        When ``file`` is not set; for CSV, when the block gives ``channels``, the sidecar is missing or not valid
        YAML, or the sidecar and the block state different rates.
    """
    fmt = block.get("format", "netcdf")
    file = block.get("file")
    if not file:
        raise RawDataError(f"{where}.file is not set; give the path of the {fmt} file")
    if fmt == "csv":
        side = sidecar_path(file, block.get("sidecar"))
        if block.get("channels"):
            raise RawDataError(
                f"{where}: a CSV import takes its channel map from the sidecar {side}; move 'channels' there"
            )
        if not os.path.exists(side):
            raise RawDataError(
                f"{where}: the sidecar {side} of {file} is missing; write the channel map there "
                "(see config/README.md, importers)"
            )
        try:
            meta = yaml.safe_load(Path(side).read_text())
        except (yaml.YAMLError, UnicodeDecodeError) as exc:
            raise RawDataError(f"{side}: not valid YAML ({exc})") from None
        meta = dict(meta or {}) if isinstance(meta, Mapping) else meta
        if isinstance(meta, dict):
            for key in ("sampling_rate_hz", "excitation_frequency_hz"):  # the config may state them instead
                if meta.get(key) is None and block.get(key) is not None:
                    meta[key] = block[key]
                elif meta.get(key) is not None and block.get(key) is not None and float(meta[key]) != float(block[key]):
                    raise RawDataError(f"{side}: {key} = {meta[key]} but {where}.{key} = {block[key]}; keep one")
        return import_spec(meta, side, fmt, file)
    return import_spec(block, where, fmt, file)


def _sampling_rate(spec: ImportSpec, samples: dict) -> float:
    stated = {r: 1.0 / s.dt for r, s in samples.items() if s.dt}
    tol = RATE_TOLERANCE[spec.format]
    rates = sorted(set(stated.values()))
    if rates and (rates[-1] - rates[0]) > tol * rates[-1]:
        raise RawDataError(
            f"{spec.file}: the channels are sampled at different rates "
            f"({ {r: round(v, 6) for r, v in stated.items()} } Hz); resample to one rate before importing"
        )
    fs_file = rates[0] if rates else None
    fs = spec.sampling_rate_hz
    if fs is None and fs_file is None:
        raise RawDataError(f"{spec.where}: the file states no sampling interval; give sampling_rate_hz")
    if fs is not None and fs_file is not None and abs(fs - fs_file) > tol * fs:
        raise RawDataError(
            f"{spec.file}: the file is sampled at {fs_file:.9g} Hz but {spec.where} says "
            f"sampling_rate_hz = {fs:g}; correct the map"
        )
    return float(fs if fs is not None else fs_file)


def import_record(block: Mapping, where: str, dual_sine: bool) -> xr.Dataset:
    """Return the raw dataset (format of ``contactid.io``) of a configured import.

    The channels are mapped by name, converted to N and m/s^2 by the map's units and sensitivities, on one time
    axis; the attributes record the source format, file and each channel's conversion.

    Parameters
    ----------
    block
        The record's config block, as ``record_spec`` reads it.
    where
        The block's place in the config, for the messages.
    dual_sine
        Whether the record is a dual-sine test (it then needs ``excitation_frequency_hz``).

    Returns
    -------
    raw : xr.Dataset
        The raw record (force [N], acceleration [m/s^2] per sensor, time [s], sensor positions [m]).

    Raises
    ------
    RawDataError
        When the channels have different lengths or no samples, a dual-sine record has no excitation frequency, or a
        converted sample is not finite.
    """
    spec = record_spec(block, where)
    samples = read_channels(spec)
    lengths = {r: s.values.size for r, s in samples.items()}
    if len(set(lengths.values())) != 1:
        raise RawDataError(f"{spec.file}: the channels have different lengths {lengths}; export whole, aligned records")
    n = next(iter(lengths.values()))
    if n == 0:
        raise RawDataError(f"{spec.file}: the channels hold no samples")
    fs = _sampling_rate(spec, samples)
    if dual_sine and spec.excitation_frequency_hz is None:
        raise RawDataError(
            f"{spec.where}: excitation_frequency_hz is missing: declare the dual-sine test frequency "
            "(the validation recovers it from the data and checks it)"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        converted = {c.role: samples[c.role].values * c.factor() for c in spec.channels}
    for c in spec.channels:
        bad = np.flatnonzero(~np.isfinite(converted[c.role]))
        if bad.size:
            raise RawDataError(
                f"{spec.file}: channel {c.channel!r} ({c.role}): sample {int(bad[0])} is "
                f"{samples[c.role].values[bad[0]]!r} ({bad.size} samples not finite in N or m/s^2); "
                "a record with gaps or overflow cannot be identified"
            )
    force = converted["force"]
    acc = np.vstack([converted[s.role] for s in spec.sensors])
    attrs = {
        "source_format": spec.format,
        "source_file": os.path.basename(spec.file),
        "conversion": "; ".join(
            f"{c.role} <- {c.channel!r} x {c.factor():.9g} ({c.units}"
            + (f", {c.sensitivity:g} {c.sensitivity_units}" if c.sensitivity else "")
            + ")"
            for c in spec.channels
        ),
    }
    if dual_sine:
        attrs["excitation_frequency_hz"] = float(spec.excitation_frequency_hz)
    return raw_dataset(
        np.arange(n) / fs, force, acc, [s.role for s in spec.sensors], [s.position_m for s in spec.sensors], fs, attrs
    )
