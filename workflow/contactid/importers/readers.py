"""Readers of the files test rigs write: universal file format dataset 58, LabVIEW TDMS and CSV.

The readers use pyuff, nptdms and pandas. Each returns, for every mapped channel, its samples (float64, as stored) and
the sampling interval the file states (or None), after checking the file's own unit labels against the channel map.
Every failure names the file and the channel.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..io import TIME_UNITS, RawDataError
from .channels import ImportSpec, check_file_unit


@dataclass
class Samples:
    """One channel as read: samples (file units) and the sampling interval stated by the file.

    Attributes
    ----------
    values
        The samples as stored, in the file's units (the channel map's ``units``) [units of ChannelSpec.units],
        shape (n_samples,).
    dt
        The sampling interval the file states [s], or None where it states none.
    """

    values: np.ndarray
    dt: float | None


def _as_samples(values, path: str, channel: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise RawDataError(f"{path}: channel {channel!r} does not hold numbers ({exc})") from None
    if arr.ndim != 1:
        raise RawDataError(f"{path}: channel {channel!r} holds an array of shape {arr.shape}; a time history is 1-D")
    return arr


def _missing(path, what, channel, available):
    avail = ", ".join(repr(a) for a in available[:20]) or "none"
    return RawDataError(f"{path}: {what} {channel!r} not found; the file has {avail}. Correct the channel map")


def datasets58(path: str, fix: str) -> list:
    """Return every dataset 58 of a universal file (pyuff's dicts).

    A file pyuff cannot read is refused with an error that names it and ends with ``fix`` (what to write instead).

    Parameters
    ----------
    path
        The universal file.
    fix
        What to write instead, the error message's end.

    Returns
    -------
    sets : list
        The file's datasets 58, as pyuff's dicts.

    Raises
    ------
    RawDataError
        Where pyuff cannot read the file.
    """
    import pyuff

    try:
        sets = pyuff.UFF(path).read_sets()
    except Exception as exc:
        raise RawDataError(f"{path}: cannot be read as a universal file ({type(exc).__name__}: {exc}); {fix}") from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    return [s for s in sets if isinstance(s, dict) and s.get("type") == 58]


def read_uff58(spec: ImportSpec) -> dict:
    """Return the time histories of a universal file (datasets 58), each channel selected by its ID line 1 (``id1``).

    Each dataset must be of function type 1 (time response) with an even abscissa.

    Parameters
    ----------
    spec
        What to import: the file and its channel map.

    Returns
    -------
    samples : dict
        {role: Samples} of every mapped channel, its sampling interval from the dataset's abscissa increment.

    Raises
    ------
    RawDataError
        For a channel not in the file, a dataset that is not an evenly sampled real time response or holds no data,
        a unit label that contradicts the map, or samples that are not a 1-D array of numbers.
    """
    path = spec.file
    by_id = {}
    for s in datasets58(path, "write the time histories as datasets 58"):
        by_id.setdefault(str(s.get("id1", "")).strip(), s)
    out = {}
    for ch in spec.channels:
        s = by_id.get(ch.channel.strip())
        if s is None:
            err = _missing(path, "dataset 58 with id1", ch.channel, list(by_id))
            raise RawDataError(f"{err} (or the file was cut short: it holds {len(by_id)} time histories)")
        if s.get("func_type") != 1:
            raise RawDataError(
                f"{path}: dataset 58 {ch.channel!r} has function type {s.get('func_type')}, not 1 "
                "(time response); export the time histories, not spectra or FRFs"
            )
        if s.get("abscissa_spacing") not in (1, None):
            raise RawDataError(f"{path}: dataset 58 {ch.channel!r} has an uneven abscissa; export evenly sampled data")
        check_file_unit(ch, s.get("ordinate_axis_units_lab"), path)
        data = s.get("data")
        if data is None:
            raise RawDataError(f"{path}: dataset 58 {ch.channel!r} holds no data")
        if np.iscomplexobj(data):
            raise RawDataError(f"{path}: dataset 58 {ch.channel!r} holds complex numbers; a time history is real")
        dt = s.get("abscissa_inc")
        out[ch.role] = Samples(_as_samples(data, path, ch.channel), float(dt) if dt else None)
    return out


def read_tdms(spec: ImportSpec) -> dict:
    """Return the channels of a TDMS file, each selected as "group/channel".

    The sampling interval comes from the channel's ``wf_increment`` property, the unit from ``unit_string``.

    Parameters
    ----------
    spec
        What to import: the file and its channel map.

    Returns
    -------
    samples : dict
        {role: Samples} of every mapped channel.

    Raises
    ------
    RawDataError
        For a file that cannot be read as TDMS, a channel not in the file or that cannot be read, a unit label that
        contradicts the map, or samples that are not a 1-D array of numbers (a missing channel raised through
        ``_missing``).
    """  # noqa: DOC503
    from nptdms import TdmsFile

    path = spec.file
    try:
        f = TdmsFile.read(path)
        chans = {f"{g.name}/{c.name}": c for g in f.groups() for c in g.channels()}
    except Exception as exc:
        raise RawDataError(f"{path}: cannot be read as a TDMS file ({type(exc).__name__}: {exc})") from None
    out = {}
    for ch in spec.channels:
        c = chans.get(ch.channel)
        if c is None:
            raise _missing(path, "channel", ch.channel, list(chans))
        check_file_unit(ch, c.properties.get("unit_string"), path)
        try:
            data = c[:]
        except Exception as exc:
            raise RawDataError(f"{path}: channel {ch.channel!r} cannot be read ({type(exc).__name__}: {exc})") from None
        dt = c.properties.get("wf_increment")
        out[ch.role] = Samples(_as_samples(data, path, ch.channel), float(dt) if dt else None)
    return out


CSV_SEPARATORS = {",": ",", ";": ";", "\t": "\t", " ": r"\s+"}
_DECIMAL_COMMA = re.compile(r"^[-+]?\d*,\d+([eE][-+]?\d+)?$")


def csv_layout(path: str, names: Iterable[str]) -> dict:
    """Return how a CSV file is laid out, as the data loggers and spreadsheets that write them differ.

    The header row (the first line that names every column in ``names``, after any lines of metadata or comments), the
    separator (comma, semicolon, tab or blanks) and the decimal mark (a comma where the separator is not one). Read from
    the first 256 kB.

    Parameters
    ----------
    path
        The CSV file.
    names
        The columns the header row must name.

    Returns
    -------
    layout : dict
        pandas.read_csv's keywords {"sep", "decimal", "skiprows"}; {} (comma, header on the first line) where no
        line names them all, so that the missing column is named.
    """
    with open(path, encoding="utf-8-sig", errors="replace") as fh:
        lines = fh.read(262144).splitlines()
    wanted = {str(n).strip() for n in names}
    for i, line in enumerate(lines[:200]):
        for key, sep in CSV_SEPARATORS.items():

            def cells(text, key=key, sep=sep):
                return [c.strip() for c in (re.split(sep, text.strip()) if key == " " else text.split(sep))]

            if wanted <= {c.strip('"').strip("'").strip() for c in cells(line)}:
                first = cells(lines[i + 1]) if i + 1 < len(lines) else []
                decimal = "," if key != "," and any(_DECIMAL_COMMA.match(c) for c in first) else "."
                return {"sep": sep, "decimal": decimal, "skiprows": i}
    return {}


def read_csv(spec: ImportSpec) -> dict:
    """Return the columns of a CSV file with a header row, each selected by its header.

    The sampling interval comes from the time column when the sidecar names one. Lines of metadata above the header,
    semicolon, tab or blank separated columns and decimal commas are recognised (``csv_layout``).

    Parameters
    ----------
    spec
        What to import: the file, its channel map and its time column (and that column's units).

    Returns
    -------
    samples : dict
        {role: Samples} of every mapped channel.

    Raises
    ------
    RawDataError
        For a file that cannot be read as CSV with a header row, or a time column that is not evenly spaced and
        increasing (and, reading a column, for one missing or holding a cell that is not a number).
    """
    import pandas as pd

    path = spec.file
    names = [ch.channel for ch in spec.channels] + ([spec.time_column] if spec.time_column else [])
    layout = csv_layout(path, names)
    try:
        df = pd.read_csv(path, encoding="utf-8-sig", skipinitialspace=True, **layout)
    except Exception as exc:
        raise RawDataError(f"{path}: cannot be read as CSV with a header row ({type(exc).__name__}: {exc})") from None
    cols = [str(c).strip() for c in df.columns]
    df.columns = cols
    first_line = layout.get("skiprows", 0) + 2  # the file's line number of the first data row

    def column(name):
        if name not in cols:
            raise _missing(path, "column", name, cols)
        cells = df[name]
        if layout.get("decimal") == "," and not pd.api.types.is_numeric_dtype(cells):  # a text cell: unparsed
            cells = cells.astype(str).str.replace(",", ".", regex=False)
        v = pd.to_numeric(cells, errors="coerce")
        bad = np.flatnonzero(v.isna().to_numpy())
        if bad.size:
            cell = df[name].iloc[bad[0]]
            what = "an empty cell" if pd.isna(cell) else f"{str(cell)!r}"
            raise RawDataError(
                f"{path}: column {name!r} line {int(bad[0]) + first_line} holds {what}, not a number "
                "(text, a gap, or a truncated line)"
            )
        return _as_samples(v.to_numpy(), path, name)

    dt = None
    if spec.time_column:
        t = column(spec.time_column) * TIME_UNITS[spec.time_units]
        if t.size >= 2:
            steps = np.diff(t)
            dt = float(np.mean(steps))
            if not (dt > 0 and np.allclose(steps, dt, rtol=1e-4, atol=1e-9 * abs(dt))):
                raise RawDataError(
                    f"{path}: time column {spec.time_column!r} is not evenly spaced and increasing "
                    f"(steps from {steps.min():g} to {steps.max():g} s)"
                )
    return {ch.role: Samples(column(ch.channel), dt) for ch in spec.channels}


READERS = {"uff58": read_uff58, "tdms": read_tdms, "csv": read_csv}


def read_channels(spec: ImportSpec) -> dict:
    """Return {role: Samples} of the file, by the reader of ``spec.format``.

    Parameters
    ----------
    spec
        What to import: the format, the file and its channel map.

    Returns
    -------
    samples : dict
        {role: Samples} of every mapped channel.

    Raises
    ------
    RawDataError
        Where the file does not exist or is empty (and, from the reader, where it cannot be read as its format).
    """
    if not os.path.exists(spec.file):
        raise RawDataError(f"{spec.where}: file {spec.file!r} not found; correct 'file:'")
    if os.path.getsize(spec.file) == 0:
        raise RawDataError(f"{spec.file}: the file is empty (zero bytes)")
    return READERS[spec.format](spec)
