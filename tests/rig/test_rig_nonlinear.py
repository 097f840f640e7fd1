"""The nonlinear virtual rig: response control, contact physics, energy, convergence, effects."""

import copy

import numpy as np
import pytest
from contactid.io import RawDataError, read_raw, write_dataset
from contactid.rig.checks import convergence_study, effect_study, low_level_frf_check
from contactid.rig.dual_sine import dual_sine_settings, dual_sine_test
from contactid.rig.effects import EFFECTS, effect_magnitudes

FS = 5120.0


@pytest.fixture(scope="module")
def lc1(default_config):
    c = default_config
    return dual_sine_test(
        c["structure"],
        c["rig"],
        c["load_cases"]["lc1"],
        FS,
        c["rig"]["noise_fraction"],
        1,
        "lc1",
        c["structure"]["sensors"]["names"],
    )


def test_response_control_hits_table2(lc1):
    _, truth = lc1
    assert truth.attrs["control_converged"] == 1
    assert truth.attrs["A1_m_per_s2"] == pytest.approx(14.0, rel=0.01)
    assert truth.attrs["A2_m_per_s2"] == pytest.approx(34.0, rel=0.01)


def test_contact_slips_and_stays_closed(lc1):
    _, truth = lc1
    S, N = truth["S"].values, truth["N"].values
    assert np.all(N > 0)  # micro-impacts without loss of contact, as the paper reports
    assert np.ptp(N) > 5.0  # N varies
    assert np.max(np.abs(S) / (truth.attrs["friction_mu"] * N)) > 0.99  # macro-slip: S reaches mu N


def test_energy_balance_within_one_percent(lc1):
    _, truth = lc1
    assert abs(truth.attrs["energy_energy_residual"]) < 0.01
    assert truth.attrs["energy_friction_work_j"] > 0 and truth.attrs["energy_damping_work_j"] > 0


def test_strong_viscous_friction_keeps_the_rig_stable_and_its_energy_balanced(default_config):
    """sigma_2 = 2e4 N s/m (the rig allows 1e5): the step takes the viscous force explicitly, and at the default eight
    steps per sample its rate sigma_2 |dxi/dq|^2 dt was 1.96 (2 is the edge): the records blew up (energy residual
    -7.4e3, the control 60 % short). The rig now steps finer where that rate asks for it (stable_oversampling)."""
    from contactid.rig.dual_sine import build_simulator
    from contactid.rig.nonlinear import stable_oversampling

    c = copy.deepcopy(default_config)
    c["rig"]["effects"] = {"viscous_friction": 2.0e4}
    settings = dual_sine_settings(c["rig"], c["load_cases"]["lc1"], FS)
    sim = build_simulator(c["structure"], c["rig"], settings)
    rate = 2.0e4 * float(sim.red.xi @ sim.red.xi)
    assert 1.5 < rate * 1.0 / (8 * FS) < 2.0  # the default step sat at the edge
    assert rate * sim.dt <= 1.0 and sim.oversampling > 8
    assert stable_oversampling(sim.red, FS, 8, viscous=0.0) == 8  # nothing else changes
    _, truth = dual_sine_test(
        c["structure"], c["rig"], c["load_cases"]["lc1"], FS, 0.0, 1, "lc1", c["structure"]["sensors"]["names"]
    )
    assert truth.attrs["control_converged"] == 1
    assert abs(truth.attrs["energy_energy_residual"]) < 0.01
    assert truth.attrs["A1_m_per_s2"] == pytest.approx(14.0, rel=0.01)


def test_record_is_steady_whole_periods_and_truth_free(lc1, tmp_path):
    raw, truth = lc1
    f0 = raw.attrs["excitation_frequency_hz"]
    periods = raw.sizes["time"] / raw.attrs["sampling_rate_hz"] * f0
    assert periods == pytest.approx(round(periods), abs=1e-9)
    assert truth.attrs["stationarity_change_a1"] < 1e-3 and truth.attrs["stationarity_change_a3"] < 1e-3
    assert set(raw.data_vars) == {"force", "acceleration"}
    assert not any("effect" in k or k.startswith("F1") or k.startswith("target") for k in raw.attrs)
    path = tmp_path / "lc1.nc"
    write_dataset(raw, path)
    read_raw(path, dual_sine=True, min_periods=8, max_harmonic=15)


def test_snapped_frequency_gives_whole_periods():
    s = dual_sine_settings({"dual_sine": {"excitation_frequency_hz": 54.4, "record_samples": 16384}}, {}, FS)
    assert s["excitation_frequency_hz"] == pytest.approx(174 * FS / 16384)


def test_time_step_and_mode_convergence(default_config):
    c = default_config
    df = convergence_study(c["structure"], c["rig"], c["load_cases"]["lc1"], FS)
    assert df["change_pct"].notna().all() and np.isfinite(df["amplitude_m_per_s2"]).all()
    main = df[df["harmonic"].isin([1, 3])]
    assert main["change_pct"].max() < 0.5
    # harmonics of at least 1 % of the largest within 1 %; the even ones (0.5 % of it) within 1e-4 of the largest
    big = df["amplitude_m_per_s2"] >= 0.01 * df["amplitude_m_per_s2"].max()
    assert df.loc[big, "change_pct"].max() < 1.0
    absolute = df["change_pct"] / 100 * df["amplitude_m_per_s2"] / df["amplitude_m_per_s2"].max()
    assert absolute[~big].max() < 1e-4


def test_low_level_agrees_with_linear_frf(default_config):
    c = default_config
    df = low_level_frf_check(c["structure"], c["rig"], FS, 54.4, 0.002)
    assert df["difference_pct"].abs().max() < 0.5


@pytest.mark.slow  # every rig effect simulated (on the small config's shorter records)
def test_effects_off_are_bit_identical_and_on_change_the_response(default_config, small_config, lc1):
    c = default_config
    rc = copy.deepcopy(c["rig"])
    rc["effects"] = {name: 0.0 for name in EFFECTS}
    raw_off, _ = dual_sine_test(
        c["structure"],
        rc,
        c["load_cases"]["lc1"],
        FS,
        c["rig"]["noise_fraction"],
        1,
        "lc1",
        c["structure"]["sensors"]["names"],
    )
    raw0, _ = lc1
    assert np.array_equal(raw_off["acceleration"].values, raw0["acceleration"].values)
    assert np.array_equal(raw_off["force"].values, raw0["force"].values)
    s = small_config
    # contact separation at 7.1x rather than its typical 7.2x: the small config's lc1 separates there too, and
    # settles, where at 7.2x the impacts keep it from settling (a response control of 14-23 s)
    df = effect_study(
        s["structure"], s["rig"], s["load_cases"]["lc1"], FS, magnitudes={"contact_separation": 7.1}
    ).set_index("effect")
    assert set(df.index) == set(EFFECTS)
    changed = df[["F1_change_pct", "F3_change_pct", "drive_acceleration_nrmse_pct"]].abs().max(axis=1)
    assert (changed > 0.5).all(), changed
    assert df.loc["contact_separation", "min_normal_force_n"] == 0.0


def test_unknown_or_out_of_range_effect_is_refused():
    with pytest.raises(ValueError, match="unknown effect"):
        effect_magnitudes({"frictoin": 1.0})
    with pytest.raises(ValueError, match=r"allowed range \[0.0, 1.0\]"):
        effect_magnitudes({"multi_asperity_friction": 2.0})


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda ds: ds.drop_vars("acceleration"), "variable 'acceleration' is missing"),
        (lambda ds: ds.assign(acceleration=ds["acceleration"].where(ds["time"] < 1.0)), "NaN"),
        (lambda ds: ds.isel(time=slice(0, 500)), "too short for the Fourier fit"),
        (lambda ds: ds.assign(force=ds["force"].assign_attrs(units="kN")), "convert to 'N'"),
    ],
)
def test_bad_measured_records_get_clear_errors(lc1, tmp_path, mutate, message):
    raw, _ = lc1
    bad = mutate(raw.copy())
    path = tmp_path / "measured_lc.nc"
    bad.to_netcdf(path, engine="netcdf4")
    with pytest.raises(RawDataError, match=message) as err:
        read_raw(path, dual_sine=True, min_periods=8, max_harmonic=15)
    assert str(path) in str(err.value)
