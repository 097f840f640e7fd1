"""The raw checks refuse a record with the cause its numbers show (contactid.raw_checks, raw_checks_dual_sine and
raw_checks_random, contactid.io.read_raw): a dead channel as dead (not clipped), a clean periodic record as good (its
peak sample repeating every period is no flat top), a wrong sampling rate as one (not as an unsettled record), a
missing units attribute as missing, and an offset as a warning. Small synthetic records: 20 periods of 54 Hz at
5400 Hz (100 samples a period, as the shared lc1.nc)."""

import numpy as np
import pytest
from contactid.io import RawDataError, raw_dataset, read_raw
from contactid.raw_checks import flat_tops
from contactid.raw_checks_dual_sine import excitation_lines, recovered_frequency, validate_dual_sine
from contactid.raw_checks_random import validate_random_test

FS, F0, N = 5400.0, 54.0, 2000
SENSORS, POSITIONS = ["a1", "a2", "a3"], [0.55, 0.3, 0.05]
ACC = ((14.0, 0.1), (43.0, 0.4), (3.0, 0.7))  # amplitude at w and phase of each accelerometer (the 3 w: 2.4 times)


def signals(noise=0.005, f1=5.0, f3=1.2, fs=FS, f0=F0, n=N, seed=0, phase=0.0):
    """Force (lines at f0 and 3 f0) and three accelerations (harmonics 1, 3, 5) of a dual-sine test, with white noise
    of ``noise`` times each channel's rms."""
    rng = np.random.default_rng(seed)
    w, t = 2 * np.pi * f0, np.arange(n) / fs
    force = f1 * np.sin(w * t + phase) + f3 * np.sin(3 * w * t + 0.3 + phase)
    acc = np.array(
        [
            a * np.sin(w * t + p + phase) + 2.4 * a * np.sin(3 * w * t + 2 * p) + 0.05 * a * np.sin(5 * w * t)
            for a, p in ACC
        ]
    )
    force += noise * np.std(force) * rng.standard_normal(n)
    acc += noise * np.std(acc, axis=1, keepdims=True) * rng.standard_normal(acc.shape)
    return force, acc


def record(force, acc, fs=FS, f0=F0, dtype=np.float64):
    """A dual-sine raw record of the samples, declared sampled at ``fs`` (its time axis k / fs) and driven at ``f0``."""
    t = np.arange(force.size) / fs
    return raw_dataset(
        t, force.astype(dtype), acc.astype(dtype), SENSORS, POSITIONS, fs, {"excitation_frequency_hz": f0}
    )


def dual_sine(dtype=np.float64, **kw):
    return record(*signals(**kw), dtype=dtype)


# ------------------------------------------------------------------------------------------
# good records pass, without a warning
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kw",
    [
        {"noise": 0.005},  # as a rig's record
        {"noise": 0.0},  # a noise-free simulator: its peak sample repeats every period
        {"noise": 0.0, "dtype": np.float32},
        {"noise": 0.0, "phase": 0.0314},  # the peak between two equal samples
        {"noise": 0.0, "phase": 1.0},
        {"noise": 0.0, "fs": 5120.0, "f0": 54.375, "n": 8192},  # 94.2 samples a period
        {"noise": 0.0, "fs": 5120.0, "f0": 54.375, "n": 8192, "dtype": np.float32},
        {"noise": 0.005, "f1": 0.5, "f3": 3.0},  # response control asking more 3 w than w of the force
        {"noise": 1e-4, "quantise": 12},  # a 12-bit converter
        {"noise": 0.0, "quantise": 8},  # a coarse one: its top step holds several samples
    ],
)
def test_good_dual_sine_records_pass_without_warnings(kw):
    kw = dict(kw)
    dtype, bits = kw.pop("dtype", np.float64), kw.pop("quantise", None)
    fs, f0 = kw.get("fs", FS), kw.get("f0", F0)
    force, acc = signals(**kw)
    if bits:
        lsb = 2 * np.abs(acc).max(axis=1, keepdims=True) / 2**bits
        acc = np.round(acc / lsb) * lsb
    raw = record(force, acc, fs, f0, dtype)
    assert validate_dual_sine(raw, "r.nc", {}) == []
    assert all(flat_tops(x)[0] == 0 for x in raw["acceleration"].values)


def test_a_clean_single_precision_record_in_ms_passes_through_the_reader(tmp_path):
    force, acc = signals(noise=0.0)
    t_ms = (1e3 * np.arange(N) / FS).astype(np.float32)
    raw = record(force, acc, dtype=np.float32).assign_coords(time=("time", t_ms, {"units": "ms"}))
    path = tmp_path / "sim.nc"
    raw.to_netcdf(path, engine="netcdf4")
    assert validate_dual_sine(read_raw(path, dual_sine=True, max_harmonic=15), str(path), {}) == []


# ------------------------------------------------------------------------------------------
# dead channels
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "channel, samples, words",
    [
        ("a2", lambda rng: np.zeros(N), ["channel a2 is flat (all samples equal to 0 m/s^2)"]),
        ("a3", lambda rng: np.full(N, 0.37), ["channel a3 is flat (all samples equal to 0.37 m/s^2)"]),
        ("a2", lambda rng: 1e-9 * rng.standard_normal(N), ["channel a2 is flat but for noise", "of the strongest"]),
        ("a1", lambda rng: 0.5 * rng.standard_normal(N), ["do not stand out of its noise", "it records noise"]),
    ],
)
def test_a_dead_accelerometer_is_refused_as_dead(channel, samples, words):
    raw = dual_sine()
    raw["acceleration"].values[SENSORS.index(channel)] = samples(np.random.default_rng(5))
    with pytest.raises(RawDataError) as err:
        validate_dual_sine(raw, "r.nc", {})
    msg = str(err.value)
    assert msg.startswith(f"r.nc: channel {channel}: dead-channel check failed: ")
    for w in [*words, "a dead sensor, cable or a channel not recorded", "check the sensor and its cable"]:
        assert w in msg
    assert "remove it from the record and from structure.sensors" in msg and "clipping" not in msg


@pytest.mark.parametrize("samples", [np.zeros(N), 1e-3 * np.random.default_rng(2).standard_normal(N)])
def test_a_dead_force_channel_is_refused_as_dead(samples):
    raw = dual_sine()
    raw["force"].values[:] = samples
    with pytest.raises(RawDataError, match="r.nc: channel force: .*a dead force transducer") as err:
        validate_dual_sine(raw, "r.nc", {})
    assert "flat (all samples equal to 0 N)" in str(err.value) or "shows no spectral line" in str(err.value)


# ------------------------------------------------------------------------------------------
# clipping: flat tops, not repeated peaks
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("noise", [0.0, 0.005])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("level", [0.8, 0.95])
def test_a_clipped_channel_is_refused_as_clipped(noise, dtype, level):
    force, acc = signals(noise=noise)
    acc[1] = np.clip(acc[1], None, level * acc[1].max())
    with pytest.raises(RawDataError, match=r"r\.nc: channel a2: clipping check failed: \d+ samples sit at the range"):
        validate_dual_sine(record(force, acc, dtype=dtype), "r.nc", {})


def test_a_clipped_sine_holds_its_flat_tops_and_a_clean_one_none():
    x = np.sin(2 * np.pi * np.arange(N) / 100)  # 20 periods of 100 samples: the same peak sample 20 times
    assert flat_tops(x)[0] == 0 and flat_tops(x.astype(np.float32).astype(float))[0] == 0
    held, evidence = flat_tops(np.clip(x, None, 0.8))
    assert held == 420 and "occurs 420 times" in evidence  # 20 tops of 21 samples
    held, evidence = flat_tops(np.clip(x, None, 0.999))  # tops of 1 or 2 samples a period, as often as their neighbours
    assert held == 20 and "continuation runs" in evidence
    noisy = np.clip(x + 0.005 * np.random.default_rng(1).standard_normal(N), None, 0.8)
    held, evidence = flat_tops(noisy)
    assert held > 300 and "occurs" in evidence


def random_test(n=8192, seed=3):
    """A random-test record: white force through three resonances (80, 200, 420 Hz), one per accelerometer."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(seed)
    force = 0.02 * rng.standard_normal(n)
    acc = []
    for f, g in ((80.0, 30.0), (200.0, 20.0), (420.0, 10.0)):
        r, th = np.exp(-2 * np.pi * f * 0.02 / FS), 2 * np.pi * f / FS
        acc.append(g * lfilter([1.0], [1.0, -2 * r * np.cos(th), r * r], force))
    return raw_dataset(np.arange(n) / FS, force, np.array(acc), SENSORS, POSITIONS, FS)


RT = {"segment_length": 512, "blocks": 4}  # 2 x 512 x 4 samples needed
RT_CHECKS = {"max_frf_resolution_hz": 20.0}


def test_random_test_checks_accept_a_good_record_and_refuse_a_clipped_or_dead_channel():
    raw = random_test()
    assert validate_random_test(raw, "rt.nc", RT_CHECKS, **RT) == []
    for level in (0.5, 0.8):
        clipped = raw.copy(deep=True)
        a = clipped["acceleration"].values[0]
        a[:] = np.clip(a, -level * np.abs(a).max(), level * np.abs(a).max())
        with pytest.raises(RawDataError, match=r"rt\.nc: channel a1: clipping check failed: \d+ samples"):
            validate_random_test(clipped, "rt.nc", RT_CHECKS, **RT)
    dead = raw.copy(deep=True)
    dead["acceleration"].values[2] = 0.0
    with pytest.raises(RawDataError, match=r"channel a3: dead-channel check failed: channel a3 is flat \(all samples"):
        validate_random_test(dead, "rt.nc", RT_CHECKS, **RT)
    dead["acceleration"].values[2] = 1e-12 * np.random.default_rng(0).standard_normal(raw.sizes["time"])
    with pytest.raises(RawDataError, match="channel a3: dead-channel check failed: channel a3 is flat but for noise"):
        validate_random_test(dead, "rt.nc", RT_CHECKS, **RT)
    offset = raw.copy(deep=True)
    offset["force"].values[:] += 0.01
    (w,) = validate_random_test(offset, "rt.nc", RT_CHECKS, **RT)
    assert w.startswith("force: mean 0.01") and " N, 0.5 of its rms: a transducer offset or drift" in w


# ------------------------------------------------------------------------------------------
# the sampling rate and the excitation frequency
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("r", [2.0, 0.5, 3.0, 5400.0 / 5120.0, 1 / 3])
def test_a_wrong_sampling_rate_is_named_with_its_factor(r):
    force, acc = signals(n=4000)  # sampled at 5400 Hz, declared at r x 5400 Hz with the time axis to match
    with pytest.raises(RawDataError) as err:
        validate_dual_sine(record(force, acc, fs=r * FS), "r.nc", {})
    msg = str(err.value)
    assert msg.startswith("r.nc: channel force: sampling rate check failed: the record's lines are at ")
    assert f"Hz, {r:.4g} times the declared excitation_frequency_hz = 54 Hz and 3 f0 = 162 Hz" in msg
    assert f"sampling_rate_hz ({r * FS:g}) is likely {r:.4g} times the true rate (5400 Hz)" in msg
    assert "correct the one that is wrong" in msg and "transient" not in msg


def test_a_line_at_twice_the_declared_frequency_alone_is_a_factor_two():
    t = np.arange(N) / FS
    force, acc = signals()
    force = 5.0 * np.sin(2 * np.pi * 2 * F0 * t)  # a line at h = 2, nothing at h = 1 or 3
    with pytest.raises(
        RawDataError, match=r"sampling rate check failed: the record's one line is at 108 Hz .* 2 times"
    ):
        validate_dual_sine(record(force, acc), "r.nc", {})


def test_the_excitation_frequency_check_keeps_a_declared_frequency_a_little_off():
    raw = dual_sine()
    raw.attrs["excitation_frequency_hz"] = F0 * 1.01
    with pytest.raises(RawDataError) as err:
        validate_dual_sine(raw, "r.nc", {})
    msg = str(err.value)
    assert "channel force: excitation frequency check failed: the record's excitation is at 54" in msg
    assert "declares 54.54 Hz" in msg and "correct excitation_frequency_hz" in msg and "sampling rate" not in msg


def test_the_strongest_force_line_may_be_the_3w():
    force, _ = signals(f1=0.5, f3=3.0)
    f, h = recovered_frequency(force, FS, F0)
    assert h == 3 and abs(f - F0) < 1e-3
    lines = excitation_lines(force, FS, F0)
    assert lines["paired"] and lines["line_to_floor"] > 1e3


# ------------------------------------------------------------------------------------------
# units and offsets
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "var, units, words",
    [
        ("acceleration", None, "'acceleration' has no units attribute; state the units: units = 'm/s^2'"),
        ("acceleration", "", "'acceleration' has no units attribute; state the units: units = 'm/s^2'"),
        ("force", None, "'force' has no units attribute; state the units: units = 'N' (also read: 'newton')"),
        ("acceleration", "g", "'acceleration' has units 'g'; convert to 'm/s^2' (1 g = 9.80665 m/s^2)"),
    ],
)
def test_units_missing_or_wrong_are_named_with_the_fix(tmp_path, var, units, words):
    raw = dual_sine()
    if units is None:
        del raw[var].attrs["units"]
    else:
        raw[var].attrs["units"] = units
    path = tmp_path / "u.nc"
    raw.to_netcdf(path, engine="netcdf4")
    with pytest.raises(RawDataError) as err:
        read_raw(path, dual_sine=True)
    assert str(err.value).startswith(str(path)) and words in str(err.value)


def test_an_offset_is_a_warning_not_a_refusal():
    raw = dual_sine()
    raw["force"].values[:] += 2.0
    raw["acceleration"].values[0] += 1.5
    warnings = validate_dual_sine(raw, "r.nc", {})
    assert warnings == [
        "force: mean 2 N, 0.4 of its amplitude at w: a transducer offset or drift (harmless to the identification, "
        "which uses the harmonics; check the charge amplifier's zero)",
        "a1: mean 1.5 m/s^2, 0.045 of its amplitude at 3 w: an accelerometer offset or drift (harmless to the "
        "identification, which uses the harmonics; check the charge amplifier's or signal conditioner's zero)",
    ]


def test_a_driving_point_accelerance_of_the_wrong_sign_is_a_warning():
    """A passive structure's driving-point accelerance is positive-imaginary at its resonances (residues phi_d^2 > 0);
    the force's sign flipped makes it negative there: a warning naming the driving point and its resonances. A
    sensor off the driving point may have either sign."""
    import xarray as xr
    from contactid.raw_checks_random import driving_point_sign_warnings

    f = np.linspace(1.0, 500.0, 4000)
    w = 2 * np.pi * f
    shapes = np.array([[1.0, 0.8, -0.6], [0.5, -0.7, 0.9]])  # (sensor, mode); sensor 0 at the driving point
    wr = 2 * np.pi * np.array([50.0, 160.0, 320.0])
    H = sum(
        -(w**2) * np.outer(shapes[:, r] * shapes[0, r], 1 / (wr[r] ** 2 - w**2 + 0.02j * w * wr[r])) for r in range(3)
    )

    def frf(h):
        return xr.Dataset(
            {"h1_real": (("sensor", "frequency"), h.real), "h1_imag": (("sensor", "frequency"), h.imag)},
            coords={"frequency": f, "sensor": ["a1", "a2"], "position": ("sensor", [0.55, 0.3])},
        )

    assert driving_point_sign_warnings(frf(H), 0.55, (20.0, 450.0)) == []
    (msg,) = driving_point_sign_warnings(frf(-H), 0.55, (20.0, 450.0))
    assert msg.startswith("a1 (driving point)") and "50.04 Hz, 160.1 Hz, 320.3 Hz" in msg and "sign is flipped" in msg
    assert driving_point_sign_warnings(frf(-H), 0.30, (20.0, 450.0)) == []  # a2 is no driving point: not judged
    assert driving_point_sign_warnings(frf(-H), 0.40, (20.0, 450.0)) == []  # no sensor at the driving point


def test_a_record_far_from_the_random_tests_level_is_refused_naming_units():
    """The accelerance at the drive against the random test's FRF: within the factor any contact state gives
    (slip moves and damps a resonance) it passes, whichever way; 1000 times off (mm/s^2 labelled m/s^2) it is refused
    before identification, whose inverse problem would overflow on it."""
    import xarray as xr
    from contactid.raw_checks_dual_sine import LEVEL_FACTOR_LIMIT, frf_level_check

    f = np.linspace(1.0, 500.0, 500)
    frf = xr.Dataset(
        {
            "h1_real": (("sensor", "frequency"), np.full((2, f.size), 3.0)),
            "h1_imag": (("sensor", "frequency"), 4.0 * np.ones((2, f.size))),
        },
        coords={"frequency": f, "sensor": ["a1", "a2"], "position": ("sensor", [0.55, 0.3])},
    )

    def check(factor):
        amp = np.array([[5.0, 0.1, 5.0], [5.0, 0.1, 5.0], [1.0, 1.0, 1.0]]) * factor  # |H| = 5 at w and 3 w
        return xr.Dataset(
            {
                "acceleration_amplitude": (("sensor", "harmonic"), amp),
                "force_amplitude": ("harmonic", np.array([1.0, 0.0, 1.0])),
            },
            coords={"sensor": ["a1", "a2", "a9"], "position": ("sensor", [0.55, 0.3, 0.1]), "harmonic": [1, 2, 3]},
            attrs={"excitation_frequency_hz": 54.0},
        )

    for factor in (1.0, 0.3, 3.0, 0.9 * LEVEL_FACTOR_LIMIT, 1.1 / LEVEL_FACTOR_LIMIT):
        assert frf_level_check(check(factor), frf, "lc1.nc") == pytest.approx(factor)
    for factor, units in ((1000.0, "mm/s\\^2"), (1e-3, "force in mN")):
        with pytest.raises(RawDataError, match=rf"lc1.nc: level check failed: .* (1e\+03|0\.001) times .*{units}"):
            frf_level_check(check(factor), frf, "lc1.nc")
