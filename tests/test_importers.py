"""Importers (UFF58, TDMS, CSV + sidecar YAML) and the validation of raw records.

Files are written with the libraries a rig's software uses (pyuff, nptdms, plain CSV) and read back;
bad files and bad records must give a RawDataError that names the file and the problem, never a
traceback from inside numpy and never a result."""

import copy

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contactid.config import ConfigError, check_config
from contactid.importers import import_record
from contactid.importers.export import export_record
from contactid.io import RawDataError, raw_dataset, read_raw, write_dataset
from contactid.raw_checks import recovered_frequency, samples_at_limit, validate_dual_sine

FS, F0, N = 5120.0, 54.375, 16384  # 174 whole periods, as the rig's records


def dual_sine(seed=0, noise=0.005, f0=F0, n=N, fs=FS):
    """A synthetic dual-sine record (force and three accelerations with harmonics 1, 3, 5 and noise)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    w = 2 * np.pi * f0
    force = 2.0 * np.sin(w * t) + 0.4 * np.sin(3 * w * t + 0.2)
    acc = np.array(
        [
            a * np.sin(w * t + p) + 2.5 * a * np.sin(3 * w * t + 2 * p) + 0.1 * a * np.sin(5 * w * t)
            for a, p in ((14.0, 0.1), (6.0, 0.4), (1.0, 0.7))
        ]
    )
    force += noise * np.std(force) * rng.standard_normal(n)
    acc += noise * np.std(acc, axis=1, keepdims=True) * rng.standard_normal(acc.shape)
    return raw_dataset(t, force, acc, ["a1", "a2", "a3"], [0.55, 0.3, 0.05], fs, {"excitation_frequency_hz": f0})


STORAGES = {
    "si": None,
    "g_and_mV": {"force": ("mV", 2.25, "mV/N"), "acceleration": ("g", None, None)},
    "volts": {"force": ("V", 0.1, "V/kN"), "acceleration": ("mV", 10.2, "mV/g")},
}


@pytest.mark.parametrize("fmt", ["uff58", "tdms", "csv"])
@pytest.mark.parametrize("storage", list(STORAGES))
def test_round_trip_recovers_the_record_in_SI(tmp_path, fmt, storage):
    raw = dual_sine()
    block = export_record(raw, tmp_path / f"lc1.{fmt}", fmt, STORAGES[storage])
    back = import_record(block, "load_cases.lc1", dual_sine=True)
    assert back.attrs["sampling_rate_hz"] == FS and back.attrs["excitation_frequency_hz"] == F0
    np.testing.assert_allclose(back["force"].values, raw["force"].values, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(back["acceleration"].values, raw["acceleration"].values, rtol=1e-13, atol=1e-12)
    assert list(back["sensor"].values) == ["a1", "a2", "a3"]
    np.testing.assert_array_equal(back["position"].values, raw["position"].values)
    # the imported record is a valid raw record and passes the validation
    path = tmp_path / "imported.nc"
    write_dataset(back, path)
    assert validate_dual_sine(read_raw(path, dual_sine=True, max_harmonic=25), str(path), {}) == []


def test_unit_conversion_is_the_stated_one(tmp_path):
    # 1 g = 9.80665 m/s^2; 2.25 mV/N: 4.5 mV is 2 N
    raw = dual_sine(noise=0.0)
    block = export_record(
        raw, tmp_path / "r.tdms", "tdms", {"force": ("mV", 2.25, "mV/N"), "acceleration": ("g", None, None)}
    )
    from nptdms import TdmsFile

    f = TdmsFile.read(tmp_path / "r.tdms")
    np.testing.assert_allclose(f["dual_sine"]["force"][:], raw["force"].values * 2.25)
    np.testing.assert_allclose(f["dual_sine"]["a1"][:], raw["acceleration"].values[0] / 9.80665)
    assert "x 9.80665 (g)" in import_record(block, "lc1", True).attrs["conversion"]


def _block(tmp_path, fmt="tdms", storage=None):
    return export_record(dual_sine(), tmp_path / f"r.{fmt}", fmt, storage)


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda b: b["channels"]["force"].pop("units"), "force.units is missing"),
        (lambda b: b["channels"]["force"].update(units="furlong"), "is not a force unit"),
        (lambda b: b["channels"]["sensors"][0].update(units="mV"), "give sensitivity and sensitivity_units"),
        (
            lambda b: b["channels"]["sensors"][0].update(units="mV", sensitivity=-1, sensitivity_units="mV/g"),
            "positive",
        ),
        (
            lambda b: b["channels"]["sensors"][0].update(units="mV", sensitivity=10, sensitivity_units="mV/N"),
            "sensitivity_units = 'mV/N'",
        ),
        (lambda b: b["channels"]["sensors"][1].update(channel="dual_sine/a1"), "mapped twice"),
        (lambda b: b["channels"]["sensors"][2].pop("position_m"), "position_m is missing"),
        (
            lambda b: b["channels"]["sensors"][0].update(units="g"),
            "labelled 'm/s^2' in the file but the channel map says units: g",
        ),
        (
            lambda b: b["channels"]["force"].update(channel="dual_sine/F"),
            "channel 'dual_sine/F' not found; the file has",
        ),
        (
            lambda b: b.update(sampling_rate_hz=5000.0),
            "sampled at 5120 Hz but load_cases.lc1 says sampling_rate_hz = 5000",
        ),
        (lambda b: b.pop("excitation_frequency_hz"), "excitation_frequency_hz is missing"),
        (lambda b: b.update(file="nowhere.tdms"), "not found; correct 'file:'"),
    ],
)
def test_bad_channel_maps_name_the_field_and_the_fix(tmp_path, edit, message):
    block = _block(tmp_path)
    edit(block)
    with pytest.raises(RawDataError, match=message.replace("(", r"\(").replace(")", r"\)").replace("^", r"\^")):
        import_record(block, "load_cases.lc1", dual_sine=True)


def test_swapped_channels_are_refused_by_the_files_unit_labels(tmp_path):
    for fmt in ("uff58", "tdms"):
        block = _block(tmp_path, fmt)
        f, a1 = block["channels"]["force"], block["channels"]["sensors"][0]
        f["channel"], a1["channel"] = a1["channel"], f["channel"]  # force mapped onto an accelerometer
        with pytest.raises(RawDataError, match="labelled"):
            import_record(block, "load_cases.lc1", dual_sine=True)


def test_csv_sidecar_problems_name_the_sidecar(tmp_path):
    block = _block(tmp_path, "csv")
    side = tmp_path / "r.yaml"
    meta = yaml.safe_load(side.read_text())
    meta["channels"]["sensors"][0]["units"] = "furlong"
    side.write_text(yaml.safe_dump(meta))
    with pytest.raises(RawDataError, match=r"r\.yaml: a1\.units = 'furlong'"):
        import_record(block, "load_cases.lc1", dual_sine=True)
    side.unlink()
    with pytest.raises(RawDataError, match="the sidecar .*r.yaml of .*r.csv is missing"):
        import_record(block, "load_cases.lc1", dual_sine=True)


def test_csv_with_text_or_a_gap_names_the_line(tmp_path):
    block = _block(tmp_path, "csv")
    lines = (tmp_path / "r.csv").read_text().splitlines()
    cells = lines[100].split(",")
    cells[2] = "overload"
    lines[100] = ",".join(cells)
    (tmp_path / "r.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(RawDataError, match="line 101 holds 'overload', not a number"):
        import_record(block, "load_cases.lc1", dual_sine=True)


def test_config_check_refuses_an_incomplete_import_before_any_rule(default_config, tmp_path):
    cfg = copy.deepcopy(default_config)
    block = _block(tmp_path)
    block["channels"]["force"].pop("units")
    cfg["load_cases"]["lc1"] = block
    with pytest.raises(ConfigError, match="load_cases.lc1: force.units is missing"):
        check_config(cfg)
    cfg["load_cases"]["lc1"] = {"A1_m_per_s2": 14.0, "A2_m_per_s2": 34.0, "format": "csv"}
    with pytest.raises(ConfigError, match="applies to measured files only"):
        check_config(cfg)


# ------------------------------------------------------------------------------------------
# validation of raw records
# ------------------------------------------------------------------------------------------


def test_validation_passes_a_clean_record_and_recovers_its_frequency():
    raw = dual_sine()
    assert validate_dual_sine(raw, "r.nc", {}) == []
    f, h = recovered_frequency(raw["force"].values, FS, 54.4)
    assert h == 1 and abs(f - F0) < 1e-4  # 54.4 declared, 54.375 in the data


def test_clipping_frequency_and_stationarity_failures_name_channel_check_and_value():
    raw = dual_sine()
    clipped = raw.copy(deep=True)
    a = clipped["acceleration"].values
    a[1] = np.clip(a[1], None, 0.8 * a[1].max())
    with pytest.raises(RawDataError, match=r"r\.nc: channel a2: clipping check failed: \d+ samples"):
        validate_dual_sine(clipped, "r.nc", {})
    wrong = raw.copy(deep=True)
    wrong.attrs["excitation_frequency_hz"] = 54.6
    with pytest.raises(RawDataError, match="excitation frequency check failed: the record's excitation is at 54.37"):
        validate_dual_sine(wrong, "r.nc", {})
    ramp = raw.copy(deep=True)
    ramp["acceleration"].values[0] *= np.linspace(1.0, 1.2, N)
    with pytest.raises(RawDataError, match=r"channel a1: stationarity check failed: .* changes by 0\.1"):
        validate_dual_sine(ramp, "r.nc", {})
    huge = raw.copy(deep=True)
    huge["force"].values[5] = 1e308  # a scaling error, not a clipped channel
    with pytest.raises(RawDataError, match=r"channel force: magnitude check failed: \|value\| reaches 1e\+308"):
        validate_dual_sine(huge, "r.nc", {})
    # a drift within the tolerance is a warning, kept in the dataset and the report
    mild = raw.copy(deep=True)
    mild["acceleration"].values[0] *= np.linspace(1.0, 1.04, N)
    assert any(w.startswith("a1: amplitude at") for w in validate_dual_sine(mild, "r.nc", {}))


# mutations of a valid record, each a defect a user meets; every one must end in a RawDataError
def _nan(ds, i, k):
    ds["acceleration"].values[k % 3, i % N] = np.nan


def _huge(ds, i, k):
    ds["force"].values[i % N] = 1e308 * 10


def _clip(ds, i, k):
    x = ds["acceleration"].values[k % 3]
    ds["acceleration"].values[k % 3] = np.clip(x, -(0.5 + 0.4 * (i % 100) / 100) * np.abs(x).max(), None)


def _declared(ds, i, k):
    ds.attrs["excitation_frequency_hz"] = F0 * (1.0 + (0.002 + 0.2 * (i % 100) / 100) * (1 if k % 2 else -1))


def _ramp(ds, i, k):
    ds["acceleration"].values[k % 3] *= np.linspace(1.0, 1.12 + (i % 100) / 100, N)


def _truncate(ds, i, k):
    return ds.isel(time=slice(0, i % 200))


def _drop_attr(ds, i, k):
    del ds.attrs[("sampling_rate_hz", "excitation_frequency_hz")[k % 2]]


def _text_force(ds, i, k):
    return ds.assign(force=("time", np.array(["x"] * N), {"units": "N", "long_name": "f"}))


def _units(ds, i, k):
    ds["acceleration"].attrs["units"] = ("g", "mm/s", "")[k % 3]


def _transpose(ds, i, k):
    return ds.assign(force=(("sensor", "time"), ds["acceleration"].values, {"units": "N", "long_name": "f"}))


MUTATIONS = [_nan, _huge, _clip, _declared, _ramp, _truncate, _drop_attr, _text_force, _units, _transpose]
BASE = dual_sine()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mutation=st.sampled_from(MUTATIONS), i=st.integers(0, 10**6), k=st.integers(0, 10))
def test_any_defective_record_gives_a_clear_error(tmp_path, mutation, i, k):
    ds = BASE.copy(deep=True)
    ds = mutation(ds, i, k) or ds
    path = tmp_path / "bad.nc"
    ds.to_netcdf(path, engine="netcdf4")
    with pytest.raises(RawDataError) as err:
        validate_dual_sine(read_raw(path, dual_sine=True, max_harmonic=15), str(path), {})
    assert str(path) in str(err.value)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    fmt=st.sampled_from(["uff58", "tdms", "csv"]),
    cut=st.floats(0.0, 0.999),
    junk=st.binary(max_size=64),
    where=st.sampled_from(["truncate", "junk_head", "junk_tail", "zero"]),
)
def test_damaged_files_give_a_clear_error_or_a_valid_record(tmp_path_factory, fmt, cut, junk, where):
    tmp = tmp_path_factory.mktemp(fmt)
    small = dual_sine(n=2048)
    block = export_record(small, tmp / f"r.{fmt}", fmt)
    path = tmp / f"r.{fmt}"
    data = path.read_bytes()
    if where == "truncate":
        data = data[: int(cut * len(data))]
    elif where == "junk_head":
        data = junk + data[len(junk) :]
    elif where == "junk_tail":
        data = data[: int(cut * len(data))] + junk
    else:
        data = b""
    path.write_bytes(data)
    try:
        raw = import_record(block, "load_cases.lc1", dual_sine=True)
    except RawDataError as exc:
        assert "r." in str(exc) or "lc1" in str(exc)
        return
    # what survives the damage must be a whole, finite record in the raw format
    assert raw.sizes["time"] > 0 and np.isfinite(raw["force"].values).all()
    assert np.isfinite(raw["acceleration"].values).all() and raw["acceleration"].shape[0] == 3


def test_samples_at_limit_counts_flat_tops():
    x = np.sin(np.linspace(0, 20 * np.pi, 4000))
    assert samples_at_limit(x) == 1
    assert samples_at_limit(np.clip(x, -0.9, 0.9)) > 100
