"""Bounded work and early refusals: no allocation sized by a record (or by a model identified from one) beyond a stated
limit, and a random test the described structure cannot have come from refused by the stiffness step, each with an
error that names what is too large or impossible, the limit and the likely cause."""

import copy
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr
from contactid.io import RawDataError, WorkLimitError
from contactid.parameters import structure_from_config

# the other lab's rig (/work/shared/foreign/*/config.yaml): what its users tell contactid about the structure
FOREIGN_STRUCTURE = {
    "beam": {"youngs_modulus_pa": 2.12e11},
    "contact_geometry": {"tangential_lever_arm_m": 0.00485, "hanger_lever_arm_m": 0.00485},
    "block": {"rotary_inertia_kg_m2": 0.01, "string_length_m": 0.2, "string_stiffness_n_per_m": 5.0e4},
    "force_transducer_mass_kg": 0.010,
    "sensors": {"names": ["a1", "a2", "a3"], "positions_m": [0.55, 0.30, 0.05], "masses_kg": [0.005] * 3},
}
# the identified frequencies (Hz) and their standard errors of the foreign random tests (modal.nc)
FOREIGN = {
    "plain": ([54.865, 166.521, 338.102], [0.00446, 0.00293, 0.00251]),
    "clamp_slip": ([54.555, 165.599, 336.208], [0.0045, 0.0030, 0.0025]),
}
# the plain random test with its sampling rate and time axis doubled: the modal fit's frequencies in 20-450 Hz
DOUBLED_RATE = ([109.73, 318.04, 333.04], [0.0089, 0.0059, 0.0050])


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


@pytest.fixture(scope="module")
def foreign_structure(default_config):
    return _merge(default_config["structure"], FOREIGN_STRUCTURE)


def _stiction(modal_frequencies, modal_std, structure_cfg, stiction_cfg):
    from contactid.linear_chain import stiction_dataset

    modal = xr.Dataset(
        {
            "natural_frequency": ("mode", np.asarray(modal_frequencies, float)),
            "natural_frequency_std": ("mode", np.asarray(modal_std, float)),
        }
    )
    return stiction_dataset(modal, structure_cfg, stiction_cfg)


# -- B: the stiffness step refuses frequencies the structure cannot have ------------------------------------------


def test_a_doubled_sampling_rate_is_refused_naming_the_file_the_ranges_and_the_factor(
    foreign_structure, default_config
):
    from contactid.stiction_refusal import refuse_unreachable

    stiction_cfg = default_config["stiction"]
    ds = _stiction(*DOUBLED_RATE, foreign_structure, stiction_cfg)
    params = structure_from_config(foreign_structure, 1e7, 1e8)
    with pytest.raises(RawDataError) as err:
        refuse_unreachable(params, ds, stiction_cfg, "data/measured/random_test.nc", 10800.0)
    msg = str(err.value)
    assert not isinstance(err.value, WorkLimitError)
    for words in (
        "random test data/measured/random_test.nc",
        "109.7, 318, 333 Hz",  # the measured frequencies
        "the structure allows",  # the ranges
        "sigma above its highest reachable frequency",
        "sampling_rate_hz (10800 Hz) off by a factor",
        "divided by 2",
        "5400 Hz",
        "(2) the structure's description",
        "(3) the sensor positions' units",
        "not written",
    ):
        assert words in msg, words
    assert msg.index("sampling_rate_hz") < msg.index("structure's description") < msg.index("sensor positions")


def test_a_halved_sampling_rate_names_the_reciprocal_factor(foreign_structure, default_config):
    from contactid.stiction_refusal import reachability

    f, s = FOREIGN["plain"]
    f = np.asarray(f) / 2
    ds = _stiction(f, np.asarray(s) / 2, foreign_structure, default_config["stiction"])
    reach = reachability(
        structure_from_config(foreign_structure, 1e7, 1e8),
        f,
        ds["frequency_sigma"].values,
        float(ds["k_t"]),
        float(ds["k_n"]),
        ds.attrs["chi2_min"],
        default_config["stiction"]["k_t_bounds_n_per_m"],
        default_config["stiction"]["k_n_bounds_n_per_m"],
        default_config["stiction"]["stiffness_scale_sd"],
    )
    assert not reach.reachable
    assert reach.factor == pytest.approx(0.5)
    assert reach.outside_sigmas[0] < -5  # below the lowest reachable first mode


@pytest.mark.parametrize("name", sorted(FOREIGN))
def test_the_foreign_records_are_far_inside_the_structures_reach(foreign_structure, default_config, name):
    from contactid.stiction_refusal import UNREACHABLE_SIGMAS, refuse_unreachable

    ds = _stiction(*FOREIGN[name], foreign_structure, default_config["stiction"])
    reach = refuse_unreachable(
        structure_from_config(foreign_structure, 1e7, 1e8), ds, default_config["stiction"], "x.nc", 5400.0
    )
    assert reach.reachable and not reach.at_bound
    inside = np.minimum(FOREIGN[name][0] - reach.ranges_hz[:, 0], reach.ranges_hz[:, 1] - FOREIGN[name][0])
    assert np.all(inside / ds["frequency_sigma"].values > 50 * UNREACHABLE_SIGMAS)  # measured: 360-450 sigma


def test_the_project_rigs_frequencies_are_reachable(default_config):
    from contactid.beam_modes import natural_frequencies
    from contactid.stiction import frequency_sigma
    from contactid.stiction_refusal import reachability

    params = structure_from_config(default_config["structure"], 1.43e7, 2.37e7)
    f = natural_frequencies(params, 3)
    st = default_config["stiction"]
    reach = reachability(
        params,
        f,
        frequency_sigma(f, np.zeros(3), st["frequency_uncertainty_floor"]),
        1.43e7,
        2.37e7,
        0.0,
        st["k_t_bounds_n_per_m"],
        st["k_n_bounds_n_per_m"],
        st["stiffness_scale_sd"],
    )
    assert reach.reachable
    assert np.all((reach.ranges_hz[:, 0] < f) & (f < reach.ranges_hz[:, 1]))


def test_a_fit_pinned_at_a_bound_far_from_the_data_is_refused_even_within_the_ranges(foreign_structure):
    """The second criterion: every frequency within its own range, but no stiffness reproduces them together."""
    from contactid.stiction_refusal import reachability

    params = structure_from_config(foreign_structure, 1e7, 1e8)
    f = np.array([60.0, 120.0, 480.0])  # mode 1 asks for a stiff contact, mode 2 for a soft one
    sigma = 1e-3 * f
    reach = reachability(params, f, sigma, 1e9, 1e11, 5e3, stiffness_scale_sd=0.05)
    assert np.all(reach.outside_sigmas == 0)
    assert reach.at_bound and not reach.reachable
    assert "chi^2 = 5e+03" in reach.reasons[0]
    # the same fit with a misfit a reachable state can leave is not refused
    assert reachability(params, f, sigma, 1e9, 1e11, 20.0, stiffness_scale_sd=0.05).reachable


# -- A, early: FRF amplitudes in g read as m/s^2 -----------------------------------------------------------------------


def test_amplitudes_in_g_are_refused_by_the_stiffness_step_and_true_ones_pass(foreign_structure, default_config):
    from contactid.stiction_refusal import refuse_unreachable
    from contactid.updating_model import modal_predictions

    st = default_config["stiction"]
    params = structure_from_config(foreign_structure, 1e7, 1e8)
    ds = _stiction(*FOREIGN["plain"], foreign_structure, st)
    fitted = params.with_contact(float(ds["k_t"]), float(ds["k_n"]))
    fitted = fitted.replace(youngs_modulus=fitted.youngs_modulus * float(ds["stiffness_scale"]))
    residues = modal_predictions(fitted, 3)[1] * 1.02  # a measured FRF a couple of per cent off the model
    assert refuse_unreachable(params, ds, st, "rt.nc", 5400.0, residue_abs=residues).reachable
    with pytest.raises(RawDataError) as err:
        refuse_unreachable(params, ds, st, "rt.nc", 5400.0, residue_abs=residues / 9.80665)
    msg = str(err.value)
    for words in (
        "random test rt.nc",
        "0.104 times",
        "accelerations in g labelled m/s^2",
        "AMPLITUDE_FACTOR_LIMIT",
        "sensitivities",
    ):
        assert words in msg, words


# -- A: the identified model's step and the simulations' memory -------------------------------------------------------


def _identified(structure):
    from contactid.gap.model import IdentifiedModel

    return IdentifiedModel(structure, (0.005,) * 3, (3.857e7, 2.547e5, 1.0e4, 0.284, 0.397), 70.0)


def test_a_model_with_an_impossible_contact_stiffness_is_refused_before_any_allocation(foreign_structure):
    from contactid.gap.model import NONE
    from contactid.gap.simulation import simulator

    # the model the gap diagnosis got from the random test in g read as m/s^2 (model updating's k_t and k_n)
    params = structure_from_config(foreign_structure, 6.16e8, 2.49e19)
    with pytest.raises(WorkLimitError) as err:
        simulator(_identified(params), NONE, 5400.0, 54.0)
    msg = str(err.value)
    for words in (
        "GHz",
        "the normal contact's mode",
        "k_n = 2.49e+19 N/m",
        "x the sampling rate 5400 Hz",
        "above the limit of 1024",
        "MAX_STEPS_PER_SAMPLE",
        "g read as m/s^2",
        "sensitivities",
        "model_updating.json",
    ):
        assert words in msg, words


def test_legitimate_models_stay_well_within_the_step_limit(foreign_structure, default_config):
    from contactid.beam_model import assemble
    from contactid.gap.model import NONE
    from contactid.gap.simulation import simulator
    from contactid.rig.nonlinear import MAX_STEPS_PER_SAMPLE, reduced_model, stable_oversampling

    sim = simulator(_identified(structure_from_config(foreign_structure, 1.43e7, 2.53e7)), NONE, 5400.0, 54.0)
    assert sim.oversampling == 8 and round(1 / (54.0 * sim.dt)) == 800
    # the stiffest a legitimate model gets: k_n at the stiffness fit's upper bound, the viscous candidate's domain end
    red = reduced_model(assemble(structure_from_config(default_config["structure"], 1.43e7, 1e11)), 8)
    assert stable_oversampling(red, 5120.0, 8) <= MAX_STEPS_PER_SAMPLE / 4
    red = reduced_model(assemble(structure_from_config(default_config["structure"], 1.43e7, 2.37e7)), 8)
    assert stable_oversampling(red, 5120.0, 8, viscous=1e5) <= MAX_STEPS_PER_SAMPLE / 4


def test_the_harmonic_balance_grid_and_the_stored_record_are_bounded(foreign_structure):
    from contactid.gap.model import NONE
    from contactid.gap.simulation import simulator
    from contactid.rig.harmonic_balance import HarmonicBalance
    from contactid.rig.nonlinear import WORK_LIMIT_BYTES, record_bytes
    from contactid.rig.periodic_response import grid_bytes

    sim = simulator(_identified(structure_from_config(foreign_structure, 1.43e7, 2.53e7)), NONE, 5400.0, 54.0)
    n = sim.red.omega.size
    w = 2 * np.pi * 54.0
    assert grid_bytes(800, 18, n) < WORK_LIMIT_BYTES / 100  # the gap diagnosis' grid on these records
    assert record_bytes(174 * 754, n, state=False) < WORK_LIMIT_BYTES / 10  # its longest record on the project's rig
    with pytest.raises(WorkLimitError, match=r"harmonic balance: 228150400 points .*WORK_LIMIT_BYTES"):
        HarmonicBalance(sim.red, sim.contact, sim.zeta, w, 9, 228_150_400)  # the 30.6 GiB grid that crashed
    with pytest.raises(WorkLimitError, match=r"time integration: storing 1000000000 steps .*WORK_LIMIT_BYTES"):
        sim.run(np.array([1.0 + 0j]), None, w, 1_000_000_000, store_from=0)


def test_a_record_with_too_many_samples_per_period_is_refused_naming_the_record(foreign_structure):
    from contactid.gap.model import NONE
    from contactid.gap.simulation import _check_work, simulator

    sim = simulator(_identified(structure_from_config(foreign_structure, 1.43e7, 2.53e7)), NONE, 5.4e6, 54.0)
    rec = SimpleNamespace(case="lc1", fs=5.4e6, f0=54.0, periods=20)
    n_per = round(1 / (54.0 * sim.dt))
    with pytest.raises(WorkLimitError) as err:
        _check_work(sim, rec, n_per, 18, 20, True)
    msg = str(err.value)
    for words in ("gap diagnosis of lc1", "100000 samples per period", "sampling_rate_hz", "WORK_LIMIT_BYTES"):
        assert words in msg, words
    legit = SimpleNamespace(case="lc1", fs=5400.0, f0=54.0, periods=20)
    sim = simulator(_identified(structure_from_config(foreign_structure, 1.43e7, 2.53e7)), NONE, 5400.0, 54.0)
    _check_work(sim, legit, 800, 18, 20, True)  # no error


# -- signal processing: memory that does not grow with the record -----------------------------------------------------


def test_the_frf_of_a_long_record_is_averaged_in_batches_with_the_same_result(monkeypatch):
    from contactid import signals

    rng = np.random.default_rng(1)
    force = rng.standard_normal(40_000)
    resp = np.vstack([np.convolve(force, [1.0, 0.5, 0.25], "same"), np.convolve(force, [0.3, -0.2], "same")])
    whole = signals.h1_frf(force, resp, 1000.0, 1024)
    monkeypatch.setattr(signals, "ARRAY_LIMIT_BYTES", 5 * signals._segment_bytes(3, 1024))  # five segments a batch
    batched = signals.h1_frf(force, resp, 1000.0, 1024)
    assert batched.n_averages == whole.n_averages == 77
    np.testing.assert_allclose(batched.h1, whole.h1, rtol=1e-12)
    np.testing.assert_allclose(batched.coherence, whole.coherence, rtol=1e-12, atol=1e-15)
    monkeypatch.setattr(signals, "ARRAY_LIMIT_BYTES", signals._segment_bytes(3, 1024) - 1)
    with pytest.raises(WorkLimitError, match="frf.segment_length"):
        signals.h1_frf(force, resp, 1000.0, 1024)


def test_harmonic_analysis_and_synthesis_past_the_limit_work_in_blocks(monkeypatch):
    from contactid import harmonics

    fs, f0 = 5000.0, 50.0
    t = np.arange(20_000) / fs
    x = np.column_stack([np.sin(2 * np.pi * f0 * t) + 0.1 * np.cos(6 * np.pi * f0 * t), np.cos(2 * np.pi * f0 * t)])
    w = 2 * np.pi * f0
    whole = harmonics.harmonic_amplitudes(x, t, w, range(1, 6))
    coef = whole.T
    syn = harmonics.synthesize(coef, f0, t)
    monkeypatch.setattr(harmonics, "ARRAY_LIMIT_BYTES", 1000 * harmonics._design_row_bytes(11))  # blocks of 1000
    np.testing.assert_allclose(harmonics.harmonic_amplitudes(x, t, w, range(1, 6)), whole, atol=1e-12)
    np.testing.assert_allclose(harmonics.synthesize(coef, f0, t), syn, atol=1e-12)
    assert abs(whole[0, 0] - 1.0) < 1e-9 and abs(whole[2, 0] - 0.1j) < 1e-9
    monkeypatch.setattr(harmonics, "ARRAY_LIMIT_BYTES", 50 * harmonics._design_row_bytes(11))
    with pytest.raises(WorkLimitError, match="ARRAY_LIMIT_BYTES"):  # 90 samples, under one period: no blocks
        harmonics.harmonic_amplitudes(x[:90], t[:90], w, range(1, 6))
