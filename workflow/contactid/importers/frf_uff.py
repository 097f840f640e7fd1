"""Frequency response functions in universal files (datasets 58), read in as the linear chain's FRF dataset.

FRFs a lab hands over are read in as the linear chain's FRF dataset (results/linear/frf.nc); ``frf_channels`` holds
the channel map that says which FRF is each sensor's, ``frf_export`` writes the chain's FRFs out.

In a dataset 58 an FRF is function type 4 (complex ordinate) and a coherence function type 6 ("Coherence" in
the dataset's description; type 9 is a power spectral density). The FRFs must be force-normalised accelerance
(m/s^2/N, or g/N converted with 9.80665): receptance (displacement over force) and mobility (velocity over force)
are refused, never differentiated here. Each sensor's coherence is the type-6 dataset of the same response and
reference node and direction as its FRF. Nothing is guessed: the units come from the file's labels or from the map,
and where both state them they must agree.
"""

from __future__ import annotations

import os
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..io import RawDataError
from .frf_channels import ACCELERANCE_UNITS, NO_LABEL, FrfSensor, accelerance_unit, frf_sensor_map
from .readers import datasets58

FRF_FUNCTION, COHERENCE_FUNCTION = 4, 6
# other FRF kinds by unit label and by the ordinate's specific data type (8 displacement, 11 velocity)
OTHER_KINDS = {
    "m/N": "receptance (displacement over force)",
    "mm/N": "receptance (displacement over force)",
    "um/N": "receptance (displacement over force)",
    "m/s/N": "mobility (velocity over force)",
    "(m/s)/N": "mobility (velocity over force)",
    "mm/s/N": "mobility (velocity over force)",
    "N/m": "dynamic stiffness (force over displacement)",
    "N/(m/s)": "mechanical impedance (force over velocity)",
    "kg": "apparent mass (force over acceleration)",
    "N/(m/s^2)": "apparent mass (force over acceleration)",
}
SPEC_KINDS = {8: "receptance (displacement over force)", 11: "mobility (velocity over force)"}
FORCE_SPEC_TYPES = (0, 1, 9, 13)  # unknown, general, reaction force, excitation force


def uff58_sets(path: str) -> list:
    """Return every dataset 58 of a universal file (pyuff's dicts), with errors that name the file.

    Parameters
    ----------
    path
        The universal file.

    Returns
    -------
    sets : list
        pyuff's dict of every dataset 58 of the file, in its order.

    Raises
    ------
    RawDataError
        When the file does not exist or is empty (and, from the reader, when pyuff cannot read it).
    """
    if not os.path.exists(path):
        raise RawDataError(f"random_test: file {path!r} not found; correct 'file:'")
    if os.path.getsize(path) == 0:
        raise RawDataError(f"{path}: the file is empty (zero bytes)")
    return datasets58(path, "write the FRFs as datasets 58 of function type 4")


def _dof(s: Mapping) -> tuple:
    return tuple(int(s.get(k) or 0) for k in ("rsp_node", "rsp_dir", "ref_node", "ref_dir"))


def _label(s: Mapping) -> str:
    return f"{str(s.get('id1', '')).strip()!r} (node {s.get('rsp_node')} dir {s.get('rsp_dir')})"


def _matches(sensor: FrfSensor, s: Mapping) -> bool:
    if sensor.channel is not None:
        return str(s.get("id1", "")).strip() == sensor.channel.strip()
    return int(s.get("rsp_node") or 0) == sensor.node and sensor.direction in (None, int(s.get("rsp_dir") or 0))


def frf_set(sets: list, sensor: FrfSensor, path: str) -> dict:
    """Return the one function-type-4 dataset of ``sensor``.

    A missing or doubled FRF names the file, the sensor and what the file holds.

    Parameters
    ----------
    sets
        The file's datasets 58 (``uff58_sets``).
    sensor
        The sensor, with the id1 or the response node and direction of its FRF.
    path
        The file, named in the messages.

    Returns
    -------
    frf : dict
        pyuff's dict of the sensor's FRF.

    Raises
    ------
    RawDataError
        When several FRFs match the sensor, when its only datasets have another function type, or when none does.
    """
    frfs = [s for s in sets if s.get("func_type") == FRF_FUNCTION]
    found = [s for s in frfs if _matches(sensor, s)]
    if len(found) == 1:
        return found[0]
    if found:
        raise RawDataError(
            f"{path}: {len(found)} FRFs match sensor {sensor.name} ({sensor.describe()}): "
            f"{', '.join(_label(s) for s in found)}; map each sensor to one (channels.sensors[].channel or node)"
        )
    others = [s for s in sets if _matches(sensor, s)]
    if others:
        raise RawDataError(
            f"{path}: dataset 58 {_label(others[0])} of sensor {sensor.name} has function type "
            f"{others[0].get('func_type')}, not 4 (frequency response function); export the FRFs"
        )
    held = ", ".join(_label(s) for s in frfs[:20]) or "none"
    raise RawDataError(
        f"{path}: no FRF (dataset 58, function type 4) for sensor {sensor.name} ({sensor.describe()}); the file "
        f"has FRFs {held}. Correct the channel map (random_test.channels.sensors) or export that sensor's FRF"
    )


def coherence_set(sets: list, frf: Mapping, path: str) -> dict | None:
    """Return the function-type-6 dataset of the same response and reference DOF as ``frf``, or None.

    Where several share the DOF, the one with the FRF's id1 is taken.

    Parameters
    ----------
    sets
        The file's datasets 58 (``uff58_sets``).
    frf
        pyuff's dict of an FRF (``frf_set``).
    path
        The file, named in the messages.

    Returns
    -------
    coherence : dict | None
        pyuff's dict of the FRF's coherence; None where the file holds none.

    Raises
    ------
    RawDataError
        When more than one coherence belongs to the FRF.
    """
    found = [s for s in sets if s.get("func_type") == COHERENCE_FUNCTION and _dof(s) == _dof(frf)]
    if len(found) > 1:
        found = [s for s in found if str(s.get("id1", "")).strip() == str(frf.get("id1", "")).strip()]
    if len(found) > 1:
        raise RawDataError(
            f"{path}: {len(found)} coherences (function type 6) belong to the FRF {_label(frf)}; keep one"
        )
    return found[0] if found else None


def frf_units(s: Mapping, sensor: FrfSensor, path: str) -> tuple[str, float]:
    """Return the units of an FRF dataset and their factor to m/s^2/N.

    From its unit labels (numerator over denominator) and its specific data types against the map's units; refuses
    receptance, mobility and anything but accelerance.

    Parameters
    ----------
    s
        pyuff's dict of the FRF (``frf_set``).
    sensor
        The sensor it belongs to, with the units its channel map states (or None).
    path
        The file, named in the messages.

    Returns
    -------
    units : str
        The FRF's units, one of ``ACCELERANCE_UNITS``.
    factor : float
        The factor that turns values in ``units`` into m/s^2/N (m/s^2/N per unit of ``units``: 1, 9.80665 or
        1e-3) [-].

    Raises
    ------
    RawDataError
        When the FRF is not force-normalised accelerance (by its specific data types or its labels), when neither
        the file nor the map states its units, or when the two disagree.
    """
    what = f"{path}: the FRF {_label(s)} of sensor {sensor.name}"
    kind = SPEC_KINDS.get(int(s.get("ordinate_spec_data_type") or 0))
    if kind is None and int(s.get("orddenom_spec_data_type") or 0) not in FORCE_SPEC_TYPES:
        kind = "not normalised by a force (denominator specific data type " + f"{s.get('orddenom_spec_data_type')})"
    num = accelerance_unit(s.get("ordinate_axis_units_lab"))
    den = accelerance_unit(s.get("orddenom_axis_units_lab"))
    label = None if num is None else accelerance_unit(num if den is None else f"{num}/{den}")
    if kind is None and label is not None and label not in ACCELERANCE_UNITS:
        kind = OTHER_KINDS.get(label, f"labelled {label!r}")
    if kind is not None:
        raise RawDataError(
            f"{what} is {kind}; the chain needs force-normalised accelerance ({', '.join(ACCELERANCE_UNITS)}): "
            "export accelerance FRFs from the acquisition software (H1 of acceleration over force)"
        )
    if label is None and sensor.units is None:
        raise RawDataError(
            f"{what} states no units; give units: m/s^2/N (or g/N) for {sensor.name} in "
            "random_test.channels.sensors (units are never guessed)"
        )
    if label is not None and sensor.units is not None and label != sensor.units:
        raise RawDataError(
            f"{what} is labelled {label!r} but the channel map says units: {sensor.units}; "
            "correct the map (or the file)"
        )
    units = label or sensor.units
    return units, ACCELERANCE_UNITS[units]


def _abscissa(s: Mapping, path: str) -> np.ndarray:
    """Return the frequency lines (Hz) of one dataset 58."""
    data, x = s.get("data"), s.get("x")
    if data is None or x is None or len(data) < 2:
        raise RawDataError(f"{path}: dataset 58 {_label(s)} holds fewer than two lines")
    unit = str(s.get("abscissa_axis_units_lab") or "").strip()
    if unit not in NO_LABEL and unit.lower() not in ("hz", "1/s"):
        raise RawDataError(
            f"{path}: dataset 58 {_label(s)} has its abscissa in {unit!r}; export it over frequency in Hz"
        )
    return np.asarray(x, dtype=float)


def frequency_axis(sets: list, path: str, band_hz: Sequence[float]) -> np.ndarray:
    """Return the frequency lines every FRF and coherence of the file shares.

    They must be evenly spaced, increasing, and cover ``band_hz`` (modal.band_hz).

    Parameters
    ----------
    sets
        pyuff's dicts of the FRFs and coherences read (not empty).
    path
        The file, named in the messages.
    band_hz
        The modal band (modal.band_hz): lowest and highest frequency [Hz].

    Returns
    -------
    frequencies : np.ndarray
        The frequency lines [Hz], shape (n_f,) with n_f the lines of each dataset.

    Raises
    ------
    RawDataError
        When a dataset's lines differ from the first's, when the lines are not evenly spaced and increasing, or when
        they do not cover ``band_hz`` (and, from reading a dataset's abscissa, when one holds fewer than two lines or
        an abscissa in other units than Hz).
    """
    f = _abscissa(sets[0], path)
    for s in sets[1:]:
        g = _abscissa(s, path)
        if g.shape != f.shape or not np.allclose(g, f, rtol=1e-9, atol=0.0):
            raise RawDataError(
                f"{path}: dataset 58 {_label(s)} has {g.size} lines from {g[0]:g} to {g[-1]:g} Hz but "
                f"{_label(sets[0])} has {f.size} from {f[0]:g} to {f[-1]:g} Hz; export every FRF and coherence "
                "on one frequency axis"
            )
    df = (f[-1] - f[0]) / (f.size - 1)
    steps = np.diff(f)
    if not (df > 0 and np.all(np.abs(steps - df) <= 1e-6 * df)):
        raise RawDataError(
            f"{path}: the frequency lines are not evenly spaced and increasing (steps from {steps.min():.6g} to "
            f"{steps.max():.6g} Hz); the modal fit needs evenly spaced lines: export the FRFs with an even abscissa"
        )
    if f[0] > band_hz[0] or f[-1] < band_hz[1]:
        raise RawDataError(
            f"{path}: the FRFs cover {f[0]:g}-{f[-1]:g} Hz, which does not hold modal.band_hz = "
            f"[{band_hz[0]:g}, {band_hz[1]:g}] Hz; narrow modal.band_hz to the measured range or export the FRFs "
            "over the whole band"
        )
    return f


def _finite(values: np.ndarray, f: np.ndarray, what: str) -> np.ndarray:
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise RawDataError(f"{what}: line {int(bad[0])} ({f[bad[0]]:g} Hz) is {values[bad[0]]!r} ({bad.size} lines)")
    return values


def accelerance(s: Mapping, sensor: FrfSensor, f: np.ndarray, path: str) -> np.ndarray:
    """Return the FRF of ``sensor`` in m/s^2/N.

    Parameters
    ----------
    s
        pyuff's dict of the FRF (``frf_set``).
    sensor
        The sensor it belongs to.
    f
        The file's frequency lines (``frequency_axis``), named in the messages [Hz], shape (n_f,).
    path
        The file, named in the messages.

    Returns
    -------
    accelerance : np.ndarray
        The FRF, complex [m/s^2/N], shape (n_f,): one value per line of ``f``.

    Raises
    ------
    RawDataError
        When the FRF holds real numbers (and, from its checks, when its units are not accelerance's or a value is
        not finite).
    """
    units, factor = frf_units(s, sensor, path)
    data = np.asarray(s["data"])
    if not np.iscomplexobj(data):
        raise RawDataError(
            f"{path}: the FRF {_label(s)} of sensor {sensor.name} holds real numbers; an FRF is complex "
            "(export real and imaginary parts, ordinate data type 5 or 6)"
        )
    return _finite(data.astype(complex) * factor, f, f"{path}: the FRF {_label(s)} of sensor {sensor.name}")


def coherence_values(s: Mapping, f: np.ndarray, path: str) -> np.ndarray:
    """Return a coherence as read: real, finite, within [0, 1] (1e-6 of rounding above 1 clipped).

    Parameters
    ----------
    s
        pyuff's dict of the coherence (``coherence_set``).
    f
        The file's frequency lines (``frequency_axis``), named in the messages [Hz], shape (n_f,).
    path
        The file, named in the messages.

    Returns
    -------
    coherence : np.ndarray
        The coherence [-], shape (n_f,): one value per line of ``f``.

    Raises
    ------
    RawDataError
        When it holds complex numbers with an imaginary part, or a value outside [0, 1] (and, from its checks, when
        a value is not finite).
    """
    data = np.asarray(s["data"])
    what = f"{path}: the coherence {_label(s)}"
    if np.iscomplexobj(data):
        if np.any(data.imag != 0):
            raise RawDataError(f"{what} holds complex numbers; a coherence is real, in [0, 1]")
        data = data.real
    c = _finite(data.astype(float), f, what)
    worst = int(np.argmax(np.abs(c - np.clip(c, 0.0, 1.0))))
    if c[worst] < 0 or c[worst] > 1 + 1e-6:
        raise RawDataError(f"{what}: line {worst} ({f[worst]:g} Hz) is {c[worst]:g}, outside [0, 1]")
    return np.clip(c, 0.0, 1.0)


def _import_attrs(path: str, sensors: tuple, frfs: list, given: dict, f: np.ndarray) -> dict:
    import json

    return {
        "n_averages": 0,
        "segment_length": 0,
        "overlap": float("nan"),
        "window": "not stated (FRF imported from a file)",
        "sampling_rate_hz": float("nan"),
        "driving_point_sensor": sensors[0].name,
        "frf_source": f"imported from {path} (UFF58 datasets of function type 4, accelerance)",
        "source_format": "uff58_frf",
        "source_file": os.path.basename(path),
        "frequency_resolution_hz": float((f[-1] - f[0]) / (f.size - 1)),
        "conversion": "; ".join(
            f"{s.name} <- {_label(d)} x {frf_units(d, s, path)[1]:.9g} ({frf_units(d, s, path)[0]})"
            for s, d in zip(sensors, frfs)
        ),
        "coherence_given": json.dumps(given),
        "sub_records": "none: an FRF file holds no sub-record FRFs (the modal fit's sub-record uncertainty is NaN)",
    }


def measured_frf_dataset(block: Mapping, where: str, structure_cfg: Mapping, band_hz: Sequence[float]) -> xr.Dataset:
    """Return the FRF dataset of results/linear/frf.nc from a UFF58 file of accelerance FRFs.

    The file holds accelerance FRFs (function type 4) and their coherences (type 6), one per sensor of
    ``structure_cfg``; the dataset is ``linear_chain.frf_result_dataset``'s, with coherence 1 where the file gives
    none (the attribute ``coherence_given`` says which) and no sub-records.

    Parameters
    ----------
    block
        The config block of the file (``random_test``): ``file`` (the UFF58 file) and ``channels`` (the channel
        map, ``frf_sensor_map``) are read.
    where
        The block's name in the config, named in the messages.
    structure_cfg
        The config's ``structure`` block; ``sensors.names`` and ``sensors.positions_m`` are read.
    band_hz
        The modal band (modal.band_hz): lowest and highest frequency [Hz].

    Returns
    -------
    frf : xr.Dataset
        H1 accelerance [m/s^2/N] and coherence over (``sensor``, ``frequency`` [Hz]), the sensors' positions, an
        empty ``block`` dimension and the import's attributes (source, conversion, ``coherence_given``).

    Raises
    ------
    RawDataError
        When ``block`` names no file or two sensors are mapped to one FRF (and, from the readers and checks it
        calls, when the file, its datasets or the channel map are not as the chain needs).
    """
    import json

    from ..linear_chain import frf_result_dataset

    path = str(block.get("file") or "")
    if not path:
        raise RawDataError(f"{where}.file is not set; give the path of the UFF58 file of FRFs")
    sensors = frf_sensor_map(block, where, structure_cfg)
    sets = uff58_sets(path)
    frfs = [frf_set(sets, s, path) for s in sensors]
    for i, (s, d) in enumerate(zip(sensors, frfs)):
        twin = next((o.name for o, e in zip(sensors[:i], frfs[:i]) if e is d), None)
        if twin:
            raise RawDataError(f"{path}: sensors {twin} and {s.name} are both mapped to the FRF {_label(d)}")
    cohs = [coherence_set(sets, d, path) for d in frfs]
    f = frequency_axis(frfs + [c for c in cohs if c is not None], path, band_hz)
    h = np.array([accelerance(d, s, f, path) for s, d in zip(sensors, frfs)])
    coh = np.array([np.ones(f.size) if c is None else coherence_values(c, f, path) for c in cohs])
    given = {s.name: c is not None for s, c in zip(sensors, cohs)}
    ds = frf_result_dataset(
        f,
        h,
        coh,
        np.empty((0, *h.shape), dtype=complex),
        [s.name for s in sensors],
        [s.position_m for s in sensors],
        _import_attrs(path, sensors, frfs, given, f),
    )
    if not all(given.values()):
        ds["coherence"].attrs["comment"] = (
            "set to 1 for the sensors the file gives no coherence for (function type 6): "
            + json.dumps([n for n, g in given.items() if not g])
        )
    return ds
