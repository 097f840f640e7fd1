"""Reading and writing the datasets passed between rules (netCDF4 engine).

Raw format (shared by the rig, measured files and importers; see
``config/README.md``):
    force(time)               N
    acceleration(sensor, time) m/s^2
    coords: time (s; ms, us or CF dates are converted, and the axis rebuilt as t0 + k / fs in float64),
            sensor (names), position(sensor) (m from the clamp)
    global attribute sampling_rate_hz; dual-sine records add excitation_frequency_hz.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Collection, Mapping, Sequence

import numpy as np
import xarray as xr

from . import __version__

ENGINE = "netcdf4"


def _defer_pint_until_imported() -> None:
    """Keep xarray from importing pint until something else has imported it.

    xarray asks, for every index it builds, whether the values are a pint Quantity, and imports pint to know
    (0.3-0.4 s, in every job of the workflow, when pint is installed: the tests use it to read the units). No value
    can be a Quantity of a module nobody imported: until pint is in ``sys.modules`` the answer is "no type" without
    importing it, afterwards xarray's own answer. Where xarray's internals differ (another version), nothing is
    changed.
    """
    try:
        from xarray.namedarray import pycompat

        cache, real = pycompat._cached_duck_array_modules, pycompat.DuckArrayModule
    except (ImportError, AttributeError):
        return
    if not isinstance(cache, dict) or "pint" in cache:
        return

    class _PintWhenImported:
        def __getattr__(self, attr):
            """Answer "no type" / "not available" while pint is not imported, afterwards pint's own attribute."""
            if "pint" not in sys.modules and attr in ("type", "available"):
                return () if attr == "type" else False
            cache["pint"] = real("pint")
            return getattr(cache["pint"], attr)

    cache["pint"] = _PintWhenImported()


_defer_pint_until_imported()


class RawDataError(ValueError):
    """A raw record that does not follow the documented format."""


class WorkLimitError(RawDataError):
    """A computation refused because its memory would pass a stated limit.

    The memory is sized by a record or by a model identified from one; the limits are
    ``rig.nonlinear.MAX_STEPS_PER_SAMPLE`` and ``rig.nonlinear.WORK_LIMIT_BYTES``. The message says what is too large,
    the limit, which record or model quantity made it so and the likely cause (most often a record read in the wrong
    units or at the wrong sampling rate, whose identified model is then impossible).
    """


def file_digest(path: str | os.PathLike) -> str:
    """Return the sha256 of a file's bytes.

    Parameters
    ----------
    path
        The file.

    Returns
    -------
    digest : str
        The digest in hex.
    """
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def config_digest(subset: Any) -> str:
    """Return the sha256 of a config subset, serialised canonically.

    Parameters
    ----------
    subset
        The config subset: anything JSON can serialise (keys sorted; other values by their ``str``).

    Returns
    -------
    digest : str
        The digest in hex.
    """
    return hashlib.sha256(json.dumps(subset, sort_keys=True, default=str).encode()).hexdigest()


def package_digest() -> str:
    """Return the sha256 over the package's Python sources (names and bytes).

    A rule parameter, so that Snakemake reruns what a changed contactid computed (the same digest names numba's
    cache).

    Returns
    -------
    digest : str
        The digest in hex (``contactid.code_digest``).
    """
    from . import code_digest

    return code_digest()


def git_revision() -> str:
    """Return the commit hash of the package's git checkout.

    Returns
    -------
    revision : str
        The commit hash, or ``unknown`` where git or the repository is unavailable.
    """
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5, cwd=Path(__file__).resolve().parent
        )
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def provenance(
    rule: str, config_subset: Mapping[str, Any] | None = None, inputs: Mapping[str, str] | None = None
) -> dict:
    """Return the global attributes that say where a dataset comes from.

    They name the producing rule, the package version, the git revision, a digest of the config subset used and the
    inputs with their digests.

    Parameters
    ----------
    rule
        The producing rule.
    config_subset
        The config the rule read ({section or key: value}); None: nothing.
    inputs
        The rule's input files {name: path}; None: none.

    Returns
    -------
    attrs : dict
        ``producer_rule``, ``contactid_version``, ``git_revision``, ``config_digest`` and, per input,
        ``input_{name}`` (its path) and ``input_{name}_sha256``.
    """
    attrs = {
        "producer_rule": rule,
        "contactid_version": __version__,
        "git_revision": git_revision(),
        "config_digest": config_digest(config_subset if config_subset is not None else {}),
    }
    for name, path in (inputs or {}).items():
        attrs[f"input_{name}"] = str(path)
        attrs[f"input_{name}_sha256"] = file_digest(path)
    return attrs


def content_digest(ds: xr.Dataset) -> str:
    """Return the sha256 over a dataset's data variables' names, dimensions and values.

    The audit recomputes it to find datasets edited after they were written.

    Parameters
    ----------
    ds
        The dataset.

    Returns
    -------
    digest : str
        The digest in hex.
    """
    h = hashlib.sha256()
    for name in sorted(ds.data_vars):
        var = ds[name]
        h.update(name.encode())
        h.update(repr(var.dims).encode())
        values = np.asarray(var.values)
        if values.dtype.kind in "fiub":
            h.update(np.ascontiguousarray(values, dtype=np.float64).tobytes())
        else:
            h.update(repr(values.tolist()).encode())
    return h.hexdigest()


def nonfinite_variables(datasets: Mapping[str, xr.Dataset], skip: Collection[str] = ()) -> list[str]:
    """Return the variables that hold a NaN or an infinite number: where a NaN came from.

    Parameters
    ----------
    datasets
        The datasets to look through, {label: dataset}; their real and complex data variables are read.
    skip
        Names of variables left out.

    Returns
    -------
    found : list[str]
        ``label: variable`` of every such variable.
    """
    out = []
    for label, data in datasets.items():
        for name, var in data.data_vars.items():
            values = np.asarray(var.values)
            if name not in skip and values.dtype.kind in "fc" and not np.all(np.isfinite(values)):
                out.append(f"{label}: {name}")
    return out


def write_dataset(ds: xr.Dataset, path: str | os.PathLike) -> None:
    """Write ``ds`` whole or not at all: to a temporary file beside ``path``, then renamed over it.

    Every data variable must carry ``units`` and ``long_name``; the content digest is stored as the attribute
    ``content_sha256``.

    Parameters
    ----------
    ds
        The dataset.
    path
        The netCDF file to write (its directory is made where missing).

    Raises
    ------
    ValueError
        When a data variable lacks ``units`` or ``long_name``.
    """
    for name, var in ds.data_vars.items():
        missing = [a for a in ("units", "long_name") if a not in var.attrs]
        if missing:
            raise ValueError(f"variable {name!r} lacks attribute(s) {missing}")
    ds = ds.copy()
    ds.attrs["content_sha256"] = content_digest(ds)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".nc.tmp", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp, engine=ENGINE)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 is too private for a shared results tree
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write a text file whole or not at all (temporary file, then renamed over ``path``).

    Parameters
    ----------
    path
        The file to write (its directory is made where missing).
    text
        Its content.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def load_dataset(path: str | os.PathLike) -> xr.Dataset:
    """Eagerly load a dataset (the file is closed on return).

    Parameters
    ----------
    path
        The netCDF file.

    Returns
    -------
    ds : xr.Dataset
        The dataset, in memory.
    """
    return xr.load_dataset(path, engine=ENGINE)


def raw_dataset(
    time: np.ndarray,
    force: np.ndarray,
    acceleration: np.ndarray,
    sensor_names: Sequence[str],
    positions: Sequence[float] | np.ndarray,
    sampling_rate_hz: float,
    attrs: Mapping | None = None,
) -> xr.Dataset:
    """Build a raw record in the documented format.

    Parameters
    ----------
    time
        Sample times [s], shape (n_t,).
    force
        Excitation force at d_p [N], shape (n_t,).
    acceleration
        Lateral accelerations [m/s^2], shape (n_sensors, n_t).
    sensor_names
        The sensors' names, n_sensors of them.
    positions
        The sensors' distances from the clamp [m], shape (n_sensors,).
    sampling_rate_hz
        Sampling rate [Hz] (the global attribute ``sampling_rate_hz``).
    attrs
        Further global attributes (e.g. ``excitation_frequency_hz``); None: none.

    Returns
    -------
    raw : xr.Dataset
        The raw record: ``force(time)``, ``acceleration(sensor, time)``, coordinates ``time``, ``sensor`` and
        ``position(sensor)``.
    """
    ds = xr.Dataset(
        {
            "force": ("time", np.asarray(force, dtype=float), {"units": "N", "long_name": "excitation force at d_p"}),
            "acceleration": (
                ("sensor", "time"),
                np.asarray(acceleration, dtype=float),
                {"units": "m/s^2", "long_name": "lateral acceleration"},
            ),
        },
        coords={
            "time": ("time", np.asarray(time, dtype=float), {"units": "s", "long_name": "time"}),
            "sensor": ("sensor", list(sensor_names)),
            "position": (
                "sensor",
                np.asarray(positions, dtype=float),
                {"units": "m", "long_name": "distance from the clamp"},
            ),
        },
        attrs={"sampling_rate_hz": float(sampling_rate_hz), **dict(attrs or {})},
    )
    return ds


_ACC_UNITS = {"m/s^2", "m/s2", "m s-2", "m/s**2"}
_FORCE_UNITS = {"N", "newton"}
_POSITION_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
# the time axis as other tools write it: its unit (absent: seconds, the format's), in seconds
TIME_UNITS = {
    **dict.fromkeys(("s", "sec", "second", "seconds"), 1.0),
    **dict.fromkeys(("ms", "millisecond", "milliseconds"), 1e-3),
    **dict.fromkeys(("us", "microsecond", "microseconds"), 1e-6),
}


def _time_in_seconds(time: xr.DataArray, fail) -> np.ndarray:
    """Return the time coordinate in seconds (float64).

    Numbers are read in the unit their ``units`` attribute states (s, ms or us; none: s), dates and durations as
    xarray decodes CF units ("seconds since ...": seconds from the first sample). ``fail(msg)`` raises the reader's
    error.
    """
    v = time.values
    if v.dtype.kind == "M":  # dates: the first sample is t = 0
        return (v - v[0]).astype("timedelta64[ns]").astype(np.int64) * 1e-9
    if v.dtype.kind == "m":
        return v.astype("timedelta64[ns]").astype(np.int64) * 1e-9
    if v.dtype.kind not in "fiu":
        fail(f"coordinate 'time' holds values of type {v.dtype}; write seconds as numbers")
    units = str(time.attrs.get("units", "s")).strip()
    if units not in TIME_UNITS:
        fail(f"coordinate 'time' has units {units!r}; write seconds ('s'), or 'ms' or 'us'")
    return np.asarray(v, dtype=np.float64) * TIME_UNITS[units]


def _uniform_time(t: np.ndarray, stored_dtype: np.dtype, fs: float, fail) -> np.ndarray:
    """Return the record's time axis t0 + k / fs (float64), after checking that the file's times lie on it.

    The file's times ``t`` (s) must lie on it within a hundredth of a sample, or within twice what the file's number
    type resolves (float32 keeps 3.2 s to 1.2e-7 s, 128 s to 7.6e-6 s: 4 % of a sample at 5120 Hz). A time axis whose
    steps are not 1 / fs, or whose sampling_rate_hz does not match it by a hundredth of a sample over the record, is
    refused: the harmonics are read at fs.
    """
    k = np.arange(t.size)
    grid = t[0] + k / fs
    resolution = 2 * np.finfo(stored_dtype).eps * float(np.max(np.abs(t))) if stored_dtype.kind == "f" else 0.0
    off = np.abs(t - grid)
    if off.size and float(np.max(off)) > max(0.01 / fs, resolution):
        i = int(np.argmax(off))
        steps = np.diff(t)
        fail(
            f"time steps are not uniform at 1/sampling_rate_hz = {1.0 / fs:g} s: sample {i} is at {t[i]:.9g} s, "
            f"{off[i] * fs:.3g} samples from t0 + {i}/sampling_rate_hz (steps from {steps.min():g} to "
            f"{steps.max():g} s); correct sampling_rate_hz or the time coordinate"
        )
    return grid


def read_raw(  # noqa: C901
    path: str | os.PathLike, dual_sine: bool = False, min_samples: int = 16, min_periods: int = 8, max_harmonic: int = 1
) -> xr.Dataset:
    """Load and check a raw record.

    Raise :class:`RawDataError` naming the file, the field and the fix when it does not follow the documented format.
    Times in ms or us, or as CF dates, are converted to seconds and the axis rebuilt as t0 + k / fs; positions in cm
    or mm are converted to m; force and acceleration are read as float64. For dual-sine records, the record must also
    hold ``min_periods`` periods of the excitation and resolve ``max_harmonic`` harmonics below the Nyquist frequency.

    Parameters
    ----------
    path
        The netCDF raw record.
    dual_sine
        Whether it is a dual-sine record (it then needs ``excitation_frequency_hz``).
    min_samples
        The fewest samples a record may hold.
    min_periods
        The fewest periods of the excitation a dual-sine record may hold.
    max_harmonic
        The highest harmonic of the excitation a dual-sine record must resolve below the Nyquist frequency.

    Returns
    -------
    raw : xr.Dataset
        The checked record in the documented format (time in s, positions in m, float64 signals).

    Raises
    ------
    RawDataError
        When the file is missing, cannot be read as netCDF, or does not follow the documented format.
    """
    path = str(path)
    if not os.path.exists(path):
        raise RawDataError(f"{path}: file not found; set 'file:' to an existing netCDF raw record")
    try:
        ds = load_dataset(path)
    except Exception as exc:
        raise RawDataError(
            f"{path}: cannot be read as netCDF ({exc}); write it in the raw format of config/README.md"
        ) from exc

    def fail(msg):
        raise RawDataError(f"{path}: {msg} (raw format: see config/README.md)")

    for var in ("force", "acceleration"):
        if var not in ds:
            fail(f"variable '{var}' is missing")
    if ds["force"].dims != ("time",):
        fail(f"'force' must have dims ('time',), has {ds['force'].dims}")
    if set(ds["acceleration"].dims) != {"sensor", "time"}:
        fail(f"'acceleration' must have dims ('sensor', 'time'), has {ds['acceleration'].dims}")
    ds["acceleration"] = ds["acceleration"].transpose("sensor", "time")
    if "position" in ds.data_vars and ds["position"].dims == ("sensor",):
        ds = ds.set_coords("position")  # written as a variable on 'sensor' (as some tools do): the same thing
    if "position" not in ds.coords:
        fail("coordinate 'position' (m from the clamp, on 'sensor') is missing")
    if "sampling_rate_hz" not in ds.attrs:
        fail("global attribute 'sampling_rate_hz' is missing")
    if dual_sine and "excitation_frequency_hz" not in ds.attrs:
        fail("global attribute 'excitation_frequency_hz' is missing (required for dual-sine records)")
    imported = (
        "or import the file with a channel map stating the units it stores (config/README.md, Importing measured files)"
    )
    for var, main, accepted, other, convert in (
        ("force", "N", _FORCE_UNITS, "kN, lbf or volts", "convert to 'N'"),
        ("acceleration", "m/s^2", _ACC_UNITS, "g, mm/s^2 or volts", "convert to 'm/s^2' (1 g = 9.80665 m/s^2)"),
    ):
        units = ds[var].attrs.get("units")
        if units is None or (isinstance(units, str) and not units.strip()):
            also = ", ".join(repr(u) for u in sorted(accepted - {main}))
            fail(
                f"'{var}' has no units attribute; state the units: units = '{main}' (also read: {also}); a record in "
                f"{other} must be converted first, {imported}"
            )
        if not (isinstance(units, str) and units in accepted):
            fail(f"'{var}' has units {units!r}; {convert}, {imported}")
    if ds["position"].dtype.kind not in "fiu" or not np.all(np.isfinite(ds["position"].values)):
        fail("coordinate 'position' must hold finite numbers (m from the clamp)")
    units_x = str(ds["position"].attrs.get("units", "m")).strip()
    if units_x not in _POSITION_UNITS:
        fail(f"coordinate 'position' has units {units_x!r}; write metres ('m'), or 'cm' or 'mm'")
    if units_x != "m":  # stated in cm or mm: converted, as the time axis is
        ds = ds.assign_coords(
            position=(
                "sensor",
                ds["position"].values * _POSITION_UNITS[units_x],
                {**ds["position"].attrs, "units": "m"},
            )
        )
    try:
        fs_attr = float(ds.attrs["sampling_rate_hz"])
        f0_attr = float(ds.attrs.get("excitation_frequency_hz", 1.0))
    except (TypeError, ValueError):
        fail("global attributes 'sampling_rate_hz' and 'excitation_frequency_hz' must be numbers (Hz)")
    if not (np.isfinite(fs_attr) and np.isfinite(f0_attr)):
        fail("global attributes 'sampling_rate_hz' and 'excitation_frequency_hz' must be finite numbers (Hz)")
    if ds.sizes["time"] < min_samples:
        fail(f"only {ds.sizes['time']} samples; at least {min_samples} are needed")
    for var in ("force", "acceleration"):
        if ds[var].dtype.kind not in "fiu":
            fail(f"'{var}' holds values of type {ds[var].dtype}; write real floating-point numbers")
        bad = ~np.isfinite(ds[var].values)
        if bad.any():
            fail(f"'{var}' holds {int(bad.sum())} NaN or infinite samples")
    fs = float(ds.attrs["sampling_rate_hz"])
    if not fs > 0:
        fail(f"sampling_rate_hz = {fs}; must be positive")
    if "time" not in ds.coords:
        fail("coordinate 'time' (s, uniform steps of 1/sampling_rate_hz) is missing")
    t = _uniform_time(_time_in_seconds(ds["time"], fail), ds["time"].dtype, fs, fail)
    ds = ds.assign_coords(time=("time", t, {"units": "s", "long_name": "time"}))
    for var in ("force", "acceleration"):  # single-precision files (many DAQ exports) computed in double
        ds[var] = ds[var].astype(np.float64)
    if dual_sine:
        f0 = float(ds.attrs["excitation_frequency_hz"])
        if not f0 > 0:
            fail(f"excitation_frequency_hz = {f0}; must be positive")
        periods = ds.sizes["time"] / fs * f0
        if periods < min_periods:
            fail(
                f"the record holds {periods:.1f} periods of {f0:g} Hz, too short for the Fourier fit; "
                f"record at least {min_periods} periods"
            )
        if max_harmonic * f0 >= fs / 2:
            fail(
                f"sampling_rate_hz = {fs:g} cannot resolve harmonic {max_harmonic} of {f0:g} Hz; "
                f"sample faster than {2 * max_harmonic * f0:g} Hz"
            )
    return ds
