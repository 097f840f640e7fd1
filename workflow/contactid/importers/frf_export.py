"""Write FRFs and their coherences as datasets 58 of a universal file, as a modal tool reads them.

The chain's measured and LSFD-synthesised FRFs (results/linear/frf_measured.uff and frf_synthesised.uff) are
written as accelerance FRFs (function type 4) and coherences (type 6) in binary double precision, with the labels
``frf_uff`` reads back: the random test's block this writer returns imports the file again.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np

from .frf_uff import COHERENCE_FUNCTION, FRF_FUNCTION

_SIX_DIGITS = "%13.5e"  # how a universal file's header keeps the abscissa minimum and increment


def _even_axis(f: np.ndarray) -> bool:
    """Return whether the header's 6-digit minimum and increment give back exactly the lines ``f`` (Hz)."""
    inc = f[1] - f[0]
    x0, dx = float(_SIX_DIGITS % f[0]), float(_SIX_DIGITS % inc)
    return bool(np.array_equal(x0 + np.arange(f.size) * dx, f))


def _dataset58(node: int, ref_node: int, f: np.ndarray, data: np.ndarray, labels: Mapping) -> dict:
    even = _even_axis(f)
    return {
        "type": 58,
        "binary": 1,
        "id3": "",
        "id4": "",
        "id5": "",
        "ver_num": 0,
        "load_case_id": 0,
        "rsp_ent_name": "beam",
        "rsp_node": node,
        "rsp_dir": 3,
        "ref_ent_name": "beam",
        "ref_node": ref_node,
        "ref_dir": 3,
        "abscissa_spacing": int(even),
        "abscissa_inc": float(f[1] - f[0]) if even else 0.0,
        "z_axis_value": 0.0,
        "abscissa_spec_data_type": 18,
        "abscissa_len_unit_exp": 0,
        "abscissa_force_unit_exp": 0,
        "abscissa_temp_unit_exp": 0,
        "abscissa_axis_lab": "Frequency",
        "abscissa_axis_units_lab": "Hz",
        "ordinate_temp_unit_exp": 0,
        "orddenom_temp_unit_exp": 0,
        "z_axis_spec_data_type": 0,
        "z_axis_len_unit_exp": 0,
        "z_axis_force_unit_exp": 0,
        "z_axis_temp_unit_exp": 0,
        "z_axis_axis_lab": "NONE",
        "z_axis_axis_units_lab": "NONE",
        "num_pts": f.size,
        "data": data,
        "x": np.asarray(f, dtype=float),
        **labels,
    }


ACCELERANCE_LABELS = {
    "func_type": FRF_FUNCTION,
    "ordinate_spec_data_type": 12,
    "ordinate_len_unit_exp": 1,
    "ordinate_force_unit_exp": 0,
    "ordinate_axis_lab": "Acceleration",
    "ordinate_axis_units_lab": "m/s^2",
    "orddenom_spec_data_type": 13,
    "orddenom_len_unit_exp": 0,
    "orddenom_force_unit_exp": 1,
    "orddenom_axis_lab": "Force",
    "orddenom_axis_units_lab": "N",
}
COHERENCE_LABELS = {
    "func_type": COHERENCE_FUNCTION,
    "ordinate_spec_data_type": 1,
    "ordinate_len_unit_exp": 0,
    "ordinate_force_unit_exp": 0,
    "ordinate_axis_lab": "Coherence",
    "ordinate_axis_units_lab": "NONE",
    "orddenom_spec_data_type": 0,
    "orddenom_len_unit_exp": 0,
    "orddenom_force_unit_exp": 0,
    "orddenom_axis_lab": "NONE",
    "orddenom_axis_units_lab": "NONE",
}


def write_frf_uff58(
    path: Path | str,
    frequency_hz: np.ndarray,
    frf: np.ndarray,
    sensors: Iterable[str],
    coherence: np.ndarray | Sequence[np.ndarray | None] | None = None,
    description: str = "contactid FRF",
    reference: int = 0,
    labels: Mapping | None = None,
) -> dict:
    """Write accelerance FRFs and their coherences as datasets 58 of a universal file.

    The FRFs go as function type 4, binary double precision, one per sensor (id1 = the sensor's name, response
    node = its number from 1, direction 3, reference node = the number of sensor ``reference``, the driving point),
    and their coherences as function type 6 of the same nodes. Lines evenly spaced to the header's 6 digits are
    written as an even abscissa, any others with every line stored. Replaces ``path`` whole.

    Parameters
    ----------
    path
        The universal file to write.
    frequency_hz
        The frequency lines [Hz], shape (n_f,).
    frf
        The accelerance FRFs, complex [m/s^2/N] (or in the units ``labels`` states), shape (n_sensors, n_f).
    sensors
        The sensors' names, n_sensors of them, in the order of ``frf``'s rows.
    coherence
        Their coherences [-], shape (n_sensors, n_f), or a list with one row per sensor and None for a sensor
        without; None to write no coherence.
    description
        ID line 2 of every dataset (", coherence" appended on the coherences').
    reference
        Index of the driving point's sensor among ``sensors`` (the datasets' reference node is its number).
    labels
        Fields that override the FRF datasets' own (a file as another tool writes it: g/N, receptance...); None
        for none.

    Returns
    -------
    block : dict
        The random_test block that reads the file back (source measured, format uff58_frf, the file).
    """
    import pyuff

    path = Path(path)
    f = np.asarray(frequency_hz, dtype=float)
    h = np.atleast_2d(np.asarray(frf, dtype=complex))
    names = [str(s) for s in sensors]
    tmp = path.with_name(path.name + ".tmp")
    if tmp.exists():
        tmp.unlink()
    uff = pyuff.UFF(str(tmp))
    for i, name in enumerate(names):
        ids = {"id1": name, "id2": description, "func_id": i + 1}
        uff.write_sets(
            _dataset58(i + 1, reference + 1, f, h[i], {**ids, **ACCELERANCE_LABELS, **(labels or {})}),
            mode="add",
            force_double=True,
        )
    for i, name in enumerate(names):
        c = None if coherence is None else coherence[i]
        if c is not None:
            ids = {"id1": name, "id2": f"{description}, coherence", "func_id": len(names) + i + 1}
            labels = {**ids, **COHERENCE_LABELS}
            c = np.asarray(c, dtype=float)
            uff.write_sets(_dataset58(i + 1, reference + 1, f, c, labels), mode="add", force_double=True)
    os.replace(tmp, path)
    return {"source": "measured", "format": "uff58_frf", "file": str(path)}
