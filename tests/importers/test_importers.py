"""Importers (UFF58, TDMS, CSV + sidecar YAML) and the validation of raw records.

Files are written with the libraries a rig's software uses (pyuff, nptdms, plain CSV) and read back;
bad files and bad records must give a RawDataError that names the file and the problem, never a
traceback from inside numpy and never a result."""

import copy
import json

import numpy as np
import pytest
import yaml
from contactid.config import check_config
from contactid.importers import import_record
from contactid.importers.export import export_record
from contactid.io import RawDataError, raw_dataset, read_raw, write_dataset
from contactid.raw_checks import samples_at_limit
from contactid.raw_checks_dual_sine import recovered_frequency, validate_dual_sine
from contactid.schema import ConfigError
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

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


@pytest.mark.parametrize("sep, decimal", [(";", ","), ("\t", "."), ("\t", ","), (";", ".")])
def test_csv_from_loggers_and_spreadsheets_reads_as_the_plain_one(tmp_path, sep, decimal):
    """A data logger's or a spreadsheet's CSV: lines of metadata above the header, semicolon, tab or blank separated
    columns, decimal commas (a European spreadsheet's export): the same record as the plain comma CSV."""
    block = _block(tmp_path, "csv")
    plain = import_record(block, "load_cases.lc1", dual_sine=True)
    lines = (tmp_path / "r.csv").read_text().splitlines()
    text = ["Logger: DAQ-9174 export", "Date;28.11.2026", "", "# units in the sidecar"]
    for line in lines:
        cells = line.split(",")
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        text.append(sep.join(cells))
    (tmp_path / "r.csv").write_text("\n".join(text) + "\n", encoding="utf-8-sig")
    back = import_record(block, "load_cases.lc1", dual_sine=True)
    np.testing.assert_array_equal(back["force"].values, plain["force"].values)
    np.testing.assert_array_equal(back["acceleration"].values, plain["acceleration"].values)
    assert back.attrs["sampling_rate_hz"] == plain.attrs["sampling_rate_hz"]
    # a bad cell is named by its line in the file, the metadata lines counted
    bad = text[:]
    row = 4 + 1 + 99  # the 100th data row
    cells = bad[row].split(sep)
    cells[2] = "overload"
    bad[row] = sep.join(cells)
    (tmp_path / "r.csv").write_text("\n".join(bad) + "\n")
    with pytest.raises(RawDataError, match=f"line {row + 1} holds 'overload', not a number"):
        import_record(block, "load_cases.lc1", dual_sine=True)


def test_a_csv_time_column_in_milliseconds_reads_with_its_units(tmp_path):
    """A logger that writes its time column in ms: with ``time_units: ms`` in the map the same record; without, the
    column's 0.195 ms steps read as 5.12 Hz against the map's 5120 Hz, and the import stops naming both."""
    import yaml

    block = _block(tmp_path, "csv")
    plain = import_record(block, "load_cases.lc1", dual_sine=True)
    lines = (tmp_path / "r.csv").read_text().splitlines()
    rows = [lines[0]] + [",".join([repr(1e3 * float(r.split(",")[0]))] + r.split(",")[1:]) for r in lines[1:]]
    (tmp_path / "r.csv").write_text("\n".join(rows) + "\n")
    side = tmp_path / "r.yaml"
    meta = yaml.safe_load(side.read_text())
    with pytest.raises(RawDataError, match=r"sampled at 5\.12 Hz but .* sampling_rate_hz = 5120"):
        import_record(block, "load_cases.lc1", dual_sine=True)
    side.write_text(yaml.safe_dump({**meta, "time_units": "ms"}))
    back = import_record(block, "load_cases.lc1", dual_sine=True)
    np.testing.assert_array_equal(back["acceleration"].values, plain["acceleration"].values)
    np.testing.assert_allclose(back["time"].values, plain["time"].values, rtol=0, atol=1e-12)
    side.write_text(yaml.safe_dump({**meta, "time_units": "minutes"}))
    with pytest.raises(RawDataError, match="time_units = 'minutes'; give s, ms or us"):
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
    transient = raw.copy(deep=True)  # a response still settling: its first third's step the larger
    transient["acceleration"].values[0] *= 1.0 + 0.3 * np.exp(-np.arange(N) / (N / 6))
    with pytest.raises(
        RawDataError, match=r"channel a1: stationarity check failed: .* changes by 0\.1.*not as a steady"
    ):
        validate_dual_sine(transient, "r.nc", {})
    huge = raw.copy(deep=True)
    huge["force"].values[5] = 1e308  # a scaling error, not a clipped channel
    with pytest.raises(RawDataError, match=r"channel force: magnitude check failed: \|value\| reaches 1e\+308"):
        validate_dual_sine(huge, "r.nc", {})
    # a drift within the tolerance is a warning, kept in the dataset and the report
    mild = raw.copy(deep=True)
    mild["acceleration"].values[0] *= np.linspace(1.0, 1.04, N)
    assert any(w.startswith("a1: amplitude at") for w in validate_dual_sine(mild, "r.nc", {}))


def test_a_steady_drift_is_kept_for_the_gap_diagnosis_and_a_transient_or_a_strong_one_refused():
    """The rig's typical preload drift (0.1) changed lc2's third harmonic by 5.9 % from the record's first third to its
    last, steadily (steps within 10 % of each other), and the raw check refused the record at its 5 % stationarity
    tolerance: the workflow could not diagnose its own typical drift. A steady drift up to raw_checks.drift_tolerance
    (0.25) is now kept with a warning; a transient (its first step the larger) or a stronger drift is refused."""
    from contactid.raw_checks_dual_sine import steady_drift

    raw = dual_sine()
    drift = raw.copy(deep=True)
    drift["acceleration"].values[0] *= np.linspace(1.0, 1.12, N)  # thirds 1.02 / 1.06 / 1.10: 7.5 % of the whole
    warnings = validate_dual_sine(drift, "r.nc", {})
    assert any(w.startswith("a1: amplitude at") and "drifts steadily by 0.075" in w for w in warnings)
    strong = raw.copy(deep=True)
    strong["acceleration"].values[0] *= np.linspace(1.0, 1.5, N)
    with pytest.raises(
        RawDataError, match=r"changes by 0\.267 .* steadily, beyond raw_checks\.drift_tolerance = 0\.25"
    ):
        validate_dual_sine(strong, "r.nc", {})
    assert validate_dual_sine(strong, "r.nc", {"drift_tolerance": 0.3})  # kept where the user allows it
    settling = raw.copy(deep=True)  # as large a change, but decaying: a transient, refused
    settling["acceleration"].values[0] *= 1.0 + 0.25 * (1.0 - np.exp(-np.arange(N) / (N / 8)))
    with pytest.raises(RawDataError, match="not as a steady drift"):
        validate_dual_sine(settling, "r.nc", {})
    assert steady_drift(1.0, 1.05, 1.1) and steady_drift(1.1, 1.06, 1.0)
    assert not steady_drift(1.0, 1.08, 1.1)  # a transient: the first step four times the second
    assert not steady_drift(1.0, 1.06, 1.02)  # up, then down: a motion that wanders


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


def _ramp(ds, i, k):  # a steady drift beyond raw_checks.drift_tolerance (a weaker one is kept for the gap diagnosis)
    ds["acceleration"].values[k % 3] *= np.linspace(1.0, 1.5 + (i % 100) / 100, N)


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


# ------------------------------------------------------------------------------------------
# measured FRFs (UFF58 function type 4 with coherence, type 6) in and out (issue 17)
# ------------------------------------------------------------------------------------------

G = 9.80665


@pytest.fixture(scope="module")
def rig_frf(small_config):
    """The rig's FRF dataset (results/linear/frf.nc's form) of a 3.2 s random test on the small config."""
    from contactid.linear_chain import frf_dataset
    from contactid.rig.random_test import random_test_datasets
    from contactid.schema import with_defaults

    cfg = with_defaults(small_config)
    cfg["random_test"]["duration_s"] = 3.2
    raw, _ = random_test_datasets(cfg["structure"], cfg["rig"], cfg["random_test"], seed=3)
    return frf_dataset(raw, 4096, 0.5, "hann", 2), cfg["structure"]


def _frf_sets(path):
    import pyuff

    return pyuff.UFF(str(path)).read_sets()


def test_rig_frfs_round_trip_through_pyuff_and_the_importer(rig_frf, tmp_path):
    from contactid.importers.frf_export import write_frf_uff58
    from contactid.importers.frf_uff import measured_frf_dataset
    from contactid.linear_chain import complex_frf

    frf, structure = rig_frf
    f, h, coh = frf["frequency"].values, complex_frf(frf), frf["coherence"].values
    block = write_frf_uff58(tmp_path / "frf.uff", f, h, frf["sensor"].values, coh)
    sets = _frf_sets(tmp_path / "frf.uff")  # what another modal tool reads: one FRF and one coherence per sensor
    assert [(s["func_type"], s["id1"].strip(), s["rsp_node"], s["ref_node"]) for s in sets] == [
        (4, "a1", 1, 1),
        (4, "a2", 2, 1),
        (4, "a3", 3, 1),
        (6, "a1", 1, 1),
        (6, "a2", 2, 1),
        (6, "a3", 3, 1),
    ]
    for i, s in enumerate(sets[:3]):
        assert s["ordinate_axis_units_lab"].strip() == "m/s^2" and s["orddenom_axis_units_lab"].strip() == "N"
        np.testing.assert_array_equal(s["x"], f)
        np.testing.assert_array_equal(s["data"], h[i])  # binary double precision: exact
        np.testing.assert_array_equal(sets[3 + i]["data"], coh[i])
    back = measured_frf_dataset(block, "random_test", structure, [20.0, 450.0])
    assert set(back.data_vars) == set(frf.data_vars) and back["h1_real"].dims == frf["h1_real"].dims
    for name in ("h1_real", "h1_imag", "coherence"):
        np.testing.assert_array_equal(back[name].values, frf[name].values)
        assert back[name].attrs["units"] == frf[name].attrs["units"]
    np.testing.assert_array_equal(back["frequency"].values, f)
    np.testing.assert_array_equal(back["position"].values, frf["position"].values)
    assert back.sizes["block"] == 0 and back.attrs["frequency_resolution_hz"] == 1.25
    assert "imported from" in back.attrs["frf_source"] and back.attrs["source_file"] == "frf.uff"
    assert json.loads(back.attrs["coherence_given"]) == {"a1": True, "a2": True, "a3": True}


def test_frfs_in_g_per_n_without_coherence_on_any_axis(rig_frf, tmp_path):
    """g/N is converted (x 9.80665); a sensor without coherence gets 1 and says so; lines whose spacing the
    header's 6 digits cannot keep are stored one by one and read back exactly."""
    from contactid.importers.frf_export import write_frf_uff58
    from contactid.importers.frf_uff import measured_frf_dataset
    from contactid.linear_chain import complex_frf

    frf, structure = rig_frf
    f = frf["frequency"].values * (1 + 1e-7)  # 1.250000125 Hz apart
    h = complex_frf(frf)
    path = tmp_path / "frf_g.uff"
    coherence = [frf["coherence"].values[0], None, None]
    write_frf_uff58(path, f, h / G, frf["sensor"].values, coherence, labels={"ordinate_axis_units_lab": "g"})
    assert _frf_sets(path)[0]["abscissa_spacing"] == 0
    back = measured_frf_dataset({"file": str(path)}, "random_test", structure, [20.0, 450.0])
    np.testing.assert_array_equal(back["frequency"].values, f)
    np.testing.assert_allclose(back["h1_real"].values, h.real, rtol=1e-15, atol=1e-15 * np.abs(h).max())
    np.testing.assert_allclose(back["h1_imag"].values, h.imag, rtol=1e-15, atol=1e-15 * np.abs(h).max())
    np.testing.assert_array_equal(back["coherence"].values[1:], 1.0)
    assert json.loads(back.attrs["coherence_given"]) == {"a1": True, "a2": False, "a3": False}
    assert '["a2", "a3"]' in back["coherence"].attrs["comment"] and "x 9.80665 (g/N)" in back.attrs["conversion"]


def _write_frfs(path, frf, sensors=("a1", "a2", "a3"), **labels):
    """The FRFs of ``sensors`` with the accelerance labels changed as given (a receptance file, say)."""
    from contactid.importers.frf_export import write_frf_uff58
    from contactid.linear_chain import complex_frf

    idx = [list(frf["sensor"].values).index(s) for s in sensors]
    return write_frf_uff58(path, frf["frequency"].values, complex_frf(frf)[idx], sensors, labels=labels)


def test_synthesised_frfs_are_the_lsfd_fit_of_the_identified_modes(rig_frf, tmp_path):
    """The identified modes' FRFs (LSFD residues and residuals in the band) on every measured line, written as
    UFF58 type 4 and read back by the importer (coherence not given) on the same lines."""
    from contactid.frf_synthesis import identified_poles, synthesised_frf
    from contactid.importers.frf_export import write_frf_uff58
    from contactid.importers.frf_uff import measured_frf_dataset
    from contactid.linear_chain import complex_frf, modal_dataset
    from contactid.modal_fit import lsfd_residues

    frf, structure = rig_frf
    modal = modal_dataset(frf, 3, [20.0, 450.0], 16)
    syn = synthesised_frf(frf, modal)
    f, h = frf["frequency"].values, complex_frf(frf)
    band = (f >= 20.0) & (f <= 450.0)
    _, fit = lsfd_residues(f[band], h[:, band], identified_poles(modal))
    np.testing.assert_allclose(syn[:, band], fit, rtol=0, atol=1e-10 * np.abs(fit).max())
    assert np.linalg.norm(syn[:, band] - h[:, band]) < 0.1 * np.linalg.norm(h[:, band])  # three modes fit the band
    block = write_frf_uff58(tmp_path / "syn.uff", f, syn, frf["sensor"].values, description="LSFD")
    back = measured_frf_dataset(block, "random_test", structure, [20.0, 450.0])
    np.testing.assert_array_equal(back["frequency"].values, f)
    np.testing.assert_array_equal(back["h1_real"].values + 1j * back["h1_imag"].values, syn)
    assert json.loads(back.attrs["coherence_given"]) == {"a1": False, "a2": False, "a3": False}


@pytest.mark.parametrize(
    "sensors, labels, band, message",
    [
        (
            ("a1", "a2", "a3"),
            {"ordinate_spec_data_type": 8, "ordinate_axis_lab": "Displacement", "ordinate_axis_units_lab": "m"},
            [20.0, 450.0],
            r"frf\.uff: the FRF 'a1' \(node 1 dir 3\) of sensor a1 is receptance \(displacement over force\); "
            r"the chain needs force-normalised accelerance .*export accelerance FRFs",
        ),
        (
            ("a1", "a2", "a3"),
            {"ordinate_spec_data_type": 1, "ordinate_axis_units_lab": "m/s"},
            [20.0, 450.0],
            r"frf\.uff: the FRF 'a1' .* is mobility \(velocity over force\)",
        ),
        (
            ("a1", "a2"),
            {},
            [20.0, 450.0],
            r"frf\.uff: no FRF \(dataset 58, function type 4\) for sensor a3 \(id1 'a3'\); the file has FRFs "
            r"'a1' \(node 1 dir 3\), 'a2' \(node 2 dir 3\)\. Correct the channel map",
        ),
        (
            ("a1", "a2", "a3"),
            {"ordinate_axis_units_lab": "NONE", "orddenom_axis_units_lab": "NONE"},
            [20.0, 450.0],
            r"frf\.uff: the FRF 'a1' .* states no units; give units: m/s\^2/N \(or g/N\) for a1 in "
            r"random_test\.channels\.sensors",
        ),
        (
            ("a1", "a2", "a3"),
            {},
            [20.0, 3000.0],
            r"frf\.uff: the FRFs cover 0-2560 Hz, which does not hold modal\.band_hz = \[20, 3000\] Hz",
        ),
    ],
    ids=["receptance", "mobility", "missing_sensor", "no_units", "band_not_covered"],
)
def test_frf_files_that_are_not_accelerance_of_every_sensor_are_refused(
    rig_frf, tmp_path, sensors, labels, band, message
):
    from contactid.importers.frf_uff import measured_frf_dataset

    frf, structure = rig_frf
    block = _write_frfs(tmp_path / "frf.uff", frf, sensors, **labels)
    with pytest.raises(RawDataError, match=message):
        measured_frf_dataset(block, "random_test", structure, band)


def test_frf_channel_map_by_node_and_the_config_checks(rig_frf, tmp_path, small_config):
    """Sensors matched by response node (the map's units where the file states none); the config's checks know
    the format: a map that leaves out a sensor, and FRFs for a load case, are refused before any rule."""
    from contactid.importers.frf_uff import measured_frf_dataset

    frf, structure = rig_frf
    block = _write_frfs(tmp_path / "frf.uff", frf, ("a3", "a2", "a1"), ordinate_axis_units_lab="NONE")
    nodes = [{"name": n, "node": k, "direction": 3, "units": "m/s^2/N"} for n, k in (("a1", 3), ("a2", 2), ("a3", 1))]
    back = measured_frf_dataset({**block, "channels": {"sensors": nodes}}, "random_test", structure, [20, 450])
    np.testing.assert_array_equal(back["h1_real"].values, frf["h1_real"].values)
    cfg = copy.deepcopy(small_config)
    cfg["random_test"] = {**block, "channels": {"sensors": nodes[:2]}}
    with pytest.raises(ConfigError, match=r"random_test: channels\.sensors does not map \['a3'\]"):
        check_config(cfg)
    cfg["random_test"] = block
    check_config(cfg)
    cfg["load_cases"]["lc1"] = dict(block)
    with pytest.raises(ConfigError, match="load_cases.lc1.format = 'uff58_frf': FRFs replace the random test only"):
        check_config(cfg)


def test_frf_resolution_check_without_a_time_record(rig_frf):
    from contactid.raw_checks_random import validate_frf_resolution

    frf, _ = rig_frf  # lines 1.25 Hz apart
    with pytest.raises(RawDataError, match=r"f\.uff: FRF resolution check failed: the lines are 1\.25 Hz apart"):
        validate_frf_resolution(frf, "f.uff", {})
    assert validate_frf_resolution(frf, "f.uff", {"max_frf_resolution_hz": 2.0}) != []
    assert validate_frf_resolution(frf, "f.uff", {"max_frf_resolution_hz": 3.0}) == []
