import copy
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from contactid.io import RawDataError, raw_dataset, read_raw, write_dataset
from contactid.rig.random_test import random_test_datasets


@pytest.fixture(scope="module")
def short_cfg(default_config):
    cfg = copy.deepcopy(default_config)
    cfg["random_test"]["duration_s"] = 2.0
    return cfg


def test_same_seed_same_bytes_other_seed_other_noise(short_cfg):
    c = short_cfg
    raw1, _ = random_test_datasets(c["structure"], c["rig"], c["random_test"], seed=7)
    raw2, _ = random_test_datasets(c["structure"], c["rig"], c["random_test"], seed=7)
    raw3, _ = random_test_datasets(c["structure"], c["rig"], c["random_test"], seed=8)
    assert np.array_equal(raw1["acceleration"].values, raw2["acceleration"].values)
    assert np.array_equal(raw1["force"].values, raw2["force"].values)
    assert not np.allclose(raw1["force"].values, raw3["force"].values)


@pytest.mark.parametrize("damping", [0.005, lambda f: 0.002 + 1e-5 * f])
def test_the_modal_sum_is_lfilter_mode_by_mode_bit_for_bit(damping):
    # the random test's accelerations in one pass over the record (every mode's filter state at once) are the
    # numbers scipy.signal.lfilter gives mode by mode, summed over the modes in order: the rig's records stay the
    # same to the last bit
    import scipy.signal
    from contactid.beam_model import assemble
    from contactid.rig.random_test import modal_acceleration_filters, modal_acceleration_sum
    from structures import configured_structure

    filters, sens = modal_acceleration_filters(assemble(configured_structure()), damping, 1.0 / 20480.0)
    assert len(filters) > 10  # the modes below the simulation's Nyquist frequency
    rng = np.random.default_rng(3)
    f = scipy.signal.sosfilt(
        scipy.signal.butter(8, [5, 1000], "bandpass", fs=20480, output="sos"), rng.standard_normal(40000)
    )
    expected = np.zeros((sens.shape[0], f.size))
    for (num, den), part in zip(filters, sens.T):
        qdd = scipy.signal.lfilter(num, den, f)
        for channel, weight in enumerate(part):
            expected[channel] += qdd * weight
    got = modal_acceleration_sum(f, filters, sens)
    assert np.abs(expected).max() > 0 and np.array_equal(got, expected)


def test_raw_record_holds_no_truth(short_cfg, tmp_path):
    c = short_cfg
    raw, truth = random_test_datasets(c["structure"], c["rig"], c["random_test"], seed=1)
    assert set(raw.data_vars) == {"force", "acceleration"}
    assert not any(k.startswith("param_") for k in raw.attrs)
    assert "k_t" in truth and "natural_frequency" in truth
    path = tmp_path / "raw.nc"
    write_dataset(raw, path)
    back = read_raw(path)
    assert back["acceleration"].attrs["units"] == "m/s^2"
    assert back.attrs["sampling_rate_hz"] == c["random_test"]["sampling_rate_hz"]


def _raw(n=256, **kw):
    t = np.arange(n) / 1000.0
    return raw_dataset(t, np.sin(t), np.vstack([np.cos(t)] * 3), ["a1", "a2", "a3"], [0.55, 0.3, 0.05], 1000.0, **kw)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda ds: ds.drop_vars("force"), "variable 'force' is missing"),
        (lambda ds: ds.assign(force=ds["force"].where(ds["time"] < 0.1)), "NaN"),
        (lambda ds: ds.assign(acceleration=ds["acceleration"].assign_attrs(units="g")), "convert to 'm/s\\^2'"),
        (lambda ds: ds.isel(time=slice(0, 4)), "only 4 samples"),
        (lambda ds: ds.drop_vars("time"), "coordinate 'time' .* is missing"),
        (lambda ds: ds.assign_attrs(sampling_rate_hz=1001.0), "not uniform .* samples from t0"),
        (lambda ds: ds.assign_coords(time=ds["time"].assign_attrs(units="h")), "'time' has units 'h'"),
        (lambda ds: ds.assign_coords(position=ds["position"].assign_attrs(units="in")), "'position' has units 'in'"),
    ],
)
def test_bad_raw_files_get_clear_errors(tmp_path, mutate, message):
    path = tmp_path / "bad.nc"
    ds = mutate(_raw())
    for v in ds.data_vars.values():
        v.attrs.setdefault("units", "N")
        v.attrs.setdefault("long_name", "x")
    ds.to_netcdf(path, engine="netcdf4")
    with pytest.raises(RawDataError, match=message) as err:
        read_raw(path)
    assert str(path) in str(err.value)


def test_raw_files_as_other_tools_write_them_read_as_the_format(tmp_path):
    """Single precision (many DAQ exports), time in milliseconds, time as CF dates ("seconds since ..."), sensor
    positions in mm written as a variable: the same record in double precision on the exact axis t0 + k / fs, positions
    in m; a 128 s single-precision time axis (rounded to 7.6e-6 s, 4 % of a sample) too."""
    fs, n = 5120.0, 16384
    t = np.arange(n) / fs
    rng = np.random.default_rng(3)
    ref = raw_dataset(t, rng.normal(size=n), rng.normal(size=(3, n)), ["a1", "a2", "a3"], [0.55, 0.3, 0.05], fs)
    single = ref.assign_coords(time=ref["time"].astype(np.float32))
    single = single.assign(force=single["force"].astype(np.float32), acceleration=single["acceleration"].astype("f4"))
    ms = ref.assign_coords(time=("time", 1e3 * t, {"units": "ms"}))
    dates = ref.assign_coords(time=np.datetime64("2026-12-04T10:00:00") + np.round(t * 1e9).astype("timedelta64[ns]"))
    long_ = ref.assign_coords(time=("time", (t + 128.0 - t[-1]).astype(np.float32), {"units": "s"}))
    # sensor positions in mm, and written as a variable on 'sensor' instead of a coordinate
    mm = ms.assign_coords(position=("sensor", 1e3 * ref["position"].values, {"units": "mm"})).reset_coords("position")
    for name, ds in {"single": single, "ms": ms, "dates": dates, "long": long_, "mm": mm}.items():
        path = tmp_path / f"{name}.nc"
        ds.to_netcdf(path, engine="netcdf4")
        back = read_raw(path)
        t0 = float(back["time"][0])
        assert back["time"].dtype == np.float64 and back["time"].attrs["units"] == "s"
        np.testing.assert_allclose(back["time"].values, t0 + np.arange(n) / fs, rtol=0, atol=1e-12 * (1 + abs(t0)))
        assert back["force"].dtype == np.float64 == back["acceleration"].dtype
        tol = 1e-7 if name == "single" else 0  # single precision rounds the samples, nothing else does
        np.testing.assert_allclose(back["acceleration"].values, ref["acceleration"].values, rtol=tol, atol=tol * 10)
        assert t0 == pytest.approx(128.0 - t[-1] if name == "long" else 0.0, abs=1e-5)
        np.testing.assert_allclose(back["position"].values, [0.55, 0.3, 0.05], rtol=1e-12)
        assert "position" in back.coords and back["position"].attrs["units"] == "m"


def _imports_in_a_fresh_process(module: str, code: str, *args: str) -> bool:
    """Whether a new interpreter running ``code`` (with ``args`` as sys.argv[1:]) ends with ``module`` imported."""
    import subprocess
    import sys

    probe = f"{code}; import sys; print({module!r} in sys.modules)"
    out = subprocess.run([sys.executable, "-c", probe, *args], capture_output=True, text=True, check=True)
    assert out.stdout.strip() in ("True", "False"), out.stderr
    return out.stdout.strip() == "True"


def test_jobs_read_datasets_without_importing_pint_and_pint_values_still_convert(tmp_path):
    """xarray imports pint (0.3-0.4 s, installed for the units test) to check each index it builds; a job of the
    workflow, which holds no pint value, reads and writes datasets without that import. Once pint is imported, its
    quantities convert as xarray converts them (the magnitudes)."""
    import importlib.util

    assert importlib.util.find_spec("pint") is not None  # installed: otherwise this test proves nothing
    path = tmp_path / "x.nc"
    coords = {"x": ("x", [0.0, 1.0, 2.0], {"units": "s", "long_name": "time"})}
    write_dataset(xr.Dataset({"y": ("x", np.ones(3), {"units": "N", "long_name": "force"})}, coords=coords), path)
    code = (
        "import sys; from contactid.io import load_dataset; ds = load_dataset(sys.argv[1]); "
        "assert ds['x'].values.tolist() == [0.0, 1.0, 2.0]"
    )
    assert not _imports_in_a_fresh_process("pint", code, str(path))
    import pint
    from xarray.namedarray.pycompat import array_type

    assert array_type("pint") == (pint.Quantity,)
    q = pint.UnitRegistry().Quantity(np.array([0.5, 1.5]), "m")
    assert xr.Dataset(coords={"x": q})["x"].values.tolist() == [0.5, 1.5]


def test_jobs_that_fit_nothing_do_not_import_scipy_optimize():
    """The linear chain's FRF, modal-fit and raw-check jobs, and the contact-force jobs, import the modules of the
    stiffness fit and of model updating for their models and results alone; scipy.optimize (0.3 s a job) is imported
    by the fits that use it."""
    code = (
        "import contactid.linear_chain, contactid.updating, contactid.updating_model, contactid.updating_result, "
        "contactid.raw_checks, contactid.raw_checks_dual_sine, contactid.raw_checks_random, contactid.stiction, "
        "contactid.stiction_refusal"
    )
    assert not _imports_in_a_fresh_process("scipy.optimize", code)


def test_a_failed_write_leaves_the_previous_file_untouched(tmp_path, monkeypatch):
    path = tmp_path / "out.nc"
    good = xr.Dataset({"x": ("i", np.arange(4.0), {"units": "1", "long_name": "x"})})
    write_dataset(good, path)
    before = path.read_bytes()

    def broken(self, target, *a, **k):
        Path(target).write_bytes(b"CDF\x01 half a file")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(OSError, match="disk full"):
        write_dataset(good.assign(x=good["x"] * 2), path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["out.nc"]  # no temporary file left behind
