"""Write a raw record (netCDF format of ``contactid.io``) as a test rig would: UFF 58, TDMS or CSV.

A universal file with datasets 58 (pyuff), a TDMS file (nptdms) or a CSV with its sidecar YAML. Each writer returns
the import block (format, file, channel map) that reads the record back, so the round trip is checked with the same
libraries a rig's software uses.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping

import numpy as np
import xarray as xr
import yaml

from .channels import ELECTRICAL, PHYSICAL

# how each quantity is stored: (units, sensitivity, sensitivity_units); the default is SI
SI = {"force": ("N", None, None), "acceleration": ("m/s^2", None, None)}


def _stored(values: np.ndarray, units: str, sens, sens_units, quantity: str) -> np.ndarray:
    """Return SI values in the stored units (the inverse of ChannelSpec.factor)."""
    phys = PHYSICAL[quantity]
    if units in phys:
        return values / phys[units]
    num, den = sens_units.split("/", 1)
    return values / phys[den.strip("()")] * sens * ELECTRICAL[num] / ELECTRICAL[units]


def _channel_map(raw: xr.Dataset, names: Mapping, storage: Mapping) -> dict:
    def entry(quantity, channel, **extra):
        units, sens, sens_units = storage.get(quantity, SI[quantity])
        e = {"channel": channel, "units": units, **extra}
        if sens is not None:
            e.update(sensitivity=sens, sensitivity_units=sens_units)
        return e

    sensors = [
        entry("acceleration", names[str(s)], name=str(s), position_m=float(p))
        for s, p in zip(raw["sensor"].values, raw["position"].values)
    ]
    return {"force": entry("force", names["force"]), "sensors": sensors}


def _series(raw: xr.Dataset, storage: Mapping):
    """Yield (role, stored values, units) of the force and of each sensor."""
    units_f, sf, suf = storage.get("force", SI["force"])
    yield "force", _stored(raw["force"].values, units_f, sf, suf, "force"), units_f
    units_a, sa, sua = storage.get("acceleration", SI["acceleration"])
    for s, a in zip(raw["sensor"].values, raw["acceleration"].values):
        yield str(s), _stored(a, units_a, sa, sua, "acceleration"), units_a


def _block(fmt, path, raw, names, storage) -> dict:
    b = {"source": "measured", "format": fmt, "file": str(path), "channels": _channel_map(raw, names, storage)}
    if "excitation_frequency_hz" in raw.attrs:
        b["excitation_frequency_hz"] = float(raw.attrs["excitation_frequency_hz"])
    return b


def export_uff58(raw: xr.Dataset, path: str | os.PathLike, storage: Mapping | None = None) -> dict:
    """Write ``raw`` as a universal file of datasets 58 (binary, double precision), one per channel.

    Each dataset's id1 is the channel's role (force or the sensor's name); an existing file is replaced.

    Parameters
    ----------
    raw
        The raw record (netCDF format of ``contactid.io``): ``force`` [N] along time, ``acceleration`` [m/s^2] along
        (sensor, time), the ``position`` of each sensor [m] and the attributes ``sampling_rate_hz`` and (dual-sine
        records) ``excitation_frequency_hz``.
    path
        The universal file to write.
    storage
        How each quantity is stored, {quantity: (units, sensitivity, sensitivity_units)} for "force" and
        "acceleration": e.g. ("g", None, None), or ("mV", 2.25, "mV/N") for a voltage with its sensitivity; a
        quantity left out (or None) is stored in SI units.

    Returns
    -------
    block : dict
        The config block that reads the record back: source, format (uff58), file, channels (the channel map),
        excitation_frequency_hz where the record has one, and sampling_rate_hz (the header keeps the increment to 6
        digits only).
    """
    import pyuff

    storage = dict(storage or {})
    path = Path(path)
    if path.exists():
        path.unlink()
    fs = float(raw.attrs["sampling_rate_hz"])
    n = raw.sizes["time"]
    uff = pyuff.UFF(str(path))
    for node, (role, values, units) in enumerate(_series(raw, storage), start=1):
        force = role == "force"
        uff.write_sets(
            {
                "type": 58,
                "binary": 1,
                "id1": role,
                "id2": "contactid export",
                "id3": "",
                "id4": "",
                "id5": "",
                "func_type": 1,
                "func_id": node,
                "ver_num": 0,
                "load_case_id": 0,
                "rsp_ent_name": "beam",
                "rsp_node": node,
                "rsp_dir": 3,
                "ref_ent_name": "beam",
                "ref_node": 1,
                "ref_dir": 3,
                "ord_data_type": 4,
                "num_pts": n,
                "abscissa_spacing": 1,
                "abscissa_min": 0.0,
                "abscissa_inc": 1.0 / fs,
                "z_axis_value": 0.0,
                "abscissa_spec_data_type": 17,
                "abscissa_len_unit_exp": 0,
                "abscissa_force_unit_exp": 0,
                "abscissa_temp_unit_exp": 0,
                "abscissa_axis_lab": "Time",
                "abscissa_axis_units_lab": "s",
                "ordinate_spec_data_type": 13 if force else 12,
                "ordinate_len_unit_exp": 0 if force else 1,
                "ordinate_force_unit_exp": 1 if force else 0,
                "ordinate_temp_unit_exp": 0,
                "ordinate_axis_lab": "Force" if force else "Acceleration",
                "ordinate_axis_units_lab": units,
                "orddenom_spec_data_type": 0,
                "orddenom_len_unit_exp": 0,
                "orddenom_force_unit_exp": 0,
                "orddenom_temp_unit_exp": 0,
                "orddenom_axis_lab": "NONE",
                "orddenom_axis_units_lab": "NONE",
                "z_axis_spec_data_type": 0,
                "z_axis_len_unit_exp": 0,
                "z_axis_force_unit_exp": 0,
                "z_axis_temp_unit_exp": 0,
                "z_axis_axis_lab": "NONE",
                "z_axis_axis_units_lab": "NONE",
                "data": np.asarray(values, dtype=np.float64),
                "x": np.arange(n) / fs,
            },
            mode="add",
            force_double=True,
        )
    # the header keeps the increment to 6 digits: state the exact rate in the map, as the rig's software knows it
    return {**_block("uff58", path, raw, {r: r for r, _, _ in _series(raw, storage)}, storage), "sampling_rate_hz": fs}


def export_tdms(
    raw: xr.Dataset, path: str | os.PathLike, storage: Mapping | None = None, group: str = "dual_sine"
) -> dict:
    """Write ``raw`` as a TDMS file: one group, a channel per signal with wf_increment and unit_string properties.

    Parameters
    ----------
    raw
        The raw record (netCDF format of ``contactid.io``): ``force`` [N] along time, ``acceleration`` [m/s^2] along
        (sensor, time), the ``position`` of each sensor [m] and the attributes ``sampling_rate_hz`` and (dual-sine
        records) ``excitation_frequency_hz``.
    path
        The TDMS file to write.
    storage
        How each quantity is stored, {quantity: (units, sensitivity, sensitivity_units)} for "force" and
        "acceleration": e.g. ("g", None, None), or ("mV", 2.25, "mV/N") for a voltage with its sensitivity; a
        quantity left out (or None) is stored in SI units.
    group
        The TDMS group's name.

    Returns
    -------
    block : dict
        The config block that reads the record back: source, format (tdms), file, channels (the channel map, channels
        named "<group>/<role>") and excitation_frequency_hz where the record has one.
    """
    from nptdms import ChannelObject, TdmsWriter

    storage = dict(storage or {})
    fs = float(raw.attrs["sampling_rate_hz"])
    with TdmsWriter(str(path)) as w:
        w.write_segment(
            [
                ChannelObject(
                    group,
                    role,
                    np.asarray(values, dtype=np.float64),
                    properties={"wf_increment": 1.0 / fs, "wf_start_offset": 0.0, "unit_string": units},
                )
                for role, values, units in _series(raw, storage)
            ]
        )
    return _block("tdms", path, raw, {r: f"{group}/{r}" for r, _, _ in _series(raw, storage)}, storage)


def export_csv(raw: xr.Dataset, path: str | os.PathLike, storage: Mapping | None = None) -> dict:
    """Write ``raw`` as a CSV and its sidecar YAML beside it (same name, suffix .yaml) holding the channel map.

    The CSV's header is time, then one column per signal ("<role> [<units>]"), values to 17 significant digits; the
    sidecar holds sampling_rate_hz, time_column, the channel map and excitation_frequency_hz where the record has one.

    Parameters
    ----------
    raw
        The raw record (netCDF format of ``contactid.io``): ``force`` [N] along time, ``acceleration`` [m/s^2] along
        (sensor, time), the ``position`` of each sensor [m] and the attributes ``sampling_rate_hz`` and (dual-sine
        records) ``excitation_frequency_hz``.
    path
        The CSV file to write.
    storage
        How each quantity is stored, {quantity: (units, sensitivity, sensitivity_units)} for "force" and
        "acceleration": e.g. ("g", None, None), or ("mV", 2.25, "mV/N") for a voltage with its sensitivity; a
        quantity left out (or None) is stored in SI units.

    Returns
    -------
    block : dict
        The config block that reads the record back: source, format (csv) and file (the channel map is in the
        sidecar).
    """
    storage = dict(storage or {})
    path = Path(path)
    fs = float(raw.attrs["sampling_rate_hz"])
    series = list(_series(raw, storage))
    cols = ["time"] + [f"{r} [{u}]" for r, _, u in series]
    data = np.column_stack([np.arange(raw.sizes["time"]) / fs] + [v for _, v, _ in series])
    np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.17g")
    side = {
        "sampling_rate_hz": fs,
        "time_column": "time",
        "channels": _channel_map(raw, {r: f"{r} [{u}]" for r, _, u in series}, storage),
    }
    if "excitation_frequency_hz" in raw.attrs:
        side["excitation_frequency_hz"] = float(raw.attrs["excitation_frequency_hz"])
    path.with_suffix(".yaml").write_text(yaml.safe_dump(side, sort_keys=False))
    return {"source": "measured", "format": "csv", "file": str(path)}


EXPORTERS = {"uff58": export_uff58, "tdms": export_tdms, "csv": export_csv}


def export_record(raw: xr.Dataset, path: str | os.PathLike, fmt: str, storage: Mapping | None = None) -> dict:
    """Write ``raw`` as ``fmt`` (uff58, tdms, csv) with the writer of ``EXPORTERS``.

    Parameters
    ----------
    raw
        The raw record (netCDF format of ``contactid.io``): ``force`` [N] along time, ``acceleration`` [m/s^2] along
        (sensor, time), the ``position`` of each sensor [m] and the attributes ``sampling_rate_hz`` and (dual-sine
        records) ``excitation_frequency_hz``.
    path
        The file to write.
    fmt
        The format: "uff58", "tdms" or "csv".
    storage
        How each quantity is stored, e.g. accelerations in g or the force in mV: {quantity: (units, sensitivity,
        sensitivity_units)} for "force" and "acceleration", e.g. ("g", None, None), or ("mV", 2.25, "mV/N") for a
        voltage with its sensitivity; a quantity left out (or None) is stored in SI units.

    Returns
    -------
    block : dict
        The config block that reads the record back (``export_uff58``, ``export_tdms``, ``export_csv``).
    """
    return EXPORTERS[fmt](raw, path, storage)
