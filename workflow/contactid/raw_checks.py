"""Checks of a dual-sine raw record before identification: its harmonic content at the
excitation frequency and its stationarity (first against last third of the record)."""

from __future__ import annotations

from typing import Mapping

import numpy as np
import xarray as xr

from .io import RawDataError
from .signals import harmonic_content


def driving_point_index(raw: xr.Dataset, excitation_position_m: float, path: str, tol_m: float = 1e-3) -> int:
    """Index of the accelerometer at the driving point d_p."""
    pos = np.asarray(raw["position"].values, dtype=float)
    i = int(np.argmin(np.abs(pos - excitation_position_m)))
    if abs(pos[i] - excitation_position_m) > tol_m:
        raise RawDataError(f"{path}: no accelerometer at the driving point d_p = {excitation_position_m} m "
                           f"(positions {pos.tolist()} m); the response control and Table 2 refer to it")
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
            "acceleration_amplitude": (("sensor", "harmonic"), np.abs(c_acc), {"units": "m/s^2", "long_name": "harmonic amplitude"}),
            "acceleration_phase": (("sensor", "harmonic"), np.angle(c_acc), {"units": "rad", "long_name": "harmonic phase (sine reference)"}),
            "force_amplitude": ("harmonic", np.abs(c_force), {"units": "N", "long_name": "force harmonic amplitude"}),
            "force_phase": ("harmonic", np.angle(c_force), {"units": "rad", "long_name": "force harmonic phase"}),
            "stationarity_change": ("excitation_harmonic", np.abs(last / first - 1),
                                    {"units": "1", "long_name": "driving-point harmonic change, last vs first third"}),
        },
        coords={"sensor": raw["sensor"].values, "harmonic": h, "excitation_harmonic": [1, 3]},
        attrs={"A1_m_per_s2": float(np.abs(c_acc[i, 0])), "A2_m_per_s2": float(np.abs(c_acc[i, 2])) if max_harmonic >= 3 else np.nan,
               "excitation_frequency_hz": f0, "periods": float(acc.shape[1] / fs * f0), "driving_point_sensor": str(raw["sensor"].values[i])},
    )
