"""A rig whose truth is not the model (issue 15): true structure, normal-law shape, damping form, several
effects at once; the raw records carry nothing of them."""

import copy

import numpy as np
import pytest
from contactid.config import check_config
from contactid.parameters import structure_from_config
from contactid.rig.damping import damping_ratios
from contactid.rig.dual_sine import contact_parameters, dual_sine_test
from contactid.rig.integrator import normal_force
from contactid.rig.periodic_path import normal_path
from contactid.rig.random_test import random_test_datasets
from contactid.rig.structure import rig_structure
from contactid.schema import ConfigError

FS = 5120.0
PERTURBED = {
    "beam": {"youngs_modulus_pa": 2.164e11 * 1.03},
    "sensors": {"masses_kg": [0.0058 * 1.4] * 3},
    "contact_geometry": {"tangential_lever_arm_m": 0.00458 * 1.08},
    "clamp_rotational_stiffness_nm_per_rad": 2.0e5,
}


def test_true_structure_changes_the_rig_only(default_config):
    c = default_config
    rig = copy.deepcopy(c["rig"])
    rig["true_structure"] = PERTURBED
    p = rig_structure(c["structure"], rig)
    nominal = rig_structure(c["structure"], c["rig"])
    assert p.youngs_modulus == pytest.approx(1.03 * nominal.youngs_modulus)
    assert p.sensor_masses == pytest.approx(tuple(1.4 * m for m in nominal.sensor_masses))
    assert p.tangential_lever_arm == pytest.approx(1.08 * nominal.tangential_lever_arm)
    assert p.clamp_rotational_stiffness == 2.0e5 and nominal.clamp_rotational_stiffness == np.inf
    # untouched keys stay nominal, and the identification's structure is the configured one
    assert p.length == nominal.length and p.block_mass == nominal.block_mass
    assert structure_from_config(c["structure"], 1.0, 1.0).youngs_modulus == c["structure"]["beam"]["youngs_modulus_pa"]


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"beam": {"youngs_modulus": 2e11}}, r"rig.true_structure.beam.youngs_modulus is not a key of structure"),
        ({"sensors": {"masses_kg": [0.01, 0.01]}}, r"must be a list of 3 entries"),
        ({"preload_n": "75"}, r"must be a number"),
        ({"beam": {"youngs_modulus_pa": "2e11"}}, r"write 2.0e\+11"),
        ({"preload_n": -5.0}, r"must be positive"),
    ],
)
def test_bad_true_structure_is_named_with_its_fix(default_config, changes, message):
    cfg = copy.deepcopy(default_config)
    cfg["rig"]["true_structure"] = changes
    with pytest.raises(ConfigError, match=message):
        check_config(cfg)


def test_polynomial_hardening_normal_law_and_its_tangents():
    n0, k_n, k3 = 70.0, 2.37e7, 4.0e19
    d0 = n0 / k_n  # exponent 1: N0 (d0 - eta) / d0 = N0 - k_n eta
    for eta in (-8e-7, -2e-7, 0.0, 3e-7, 1e-6):
        expected = max(n0 - k_n * eta - k3 * eta**3, 0.0)
        assert normal_force(eta, 0.0, n0, d0, 1.0, 0.0, True, k3) == pytest.approx(expected, rel=1e-12, abs=1e-12)
    # loss of contact: the cubic opens the contact before the linear spring would (eta < d0 = 2.95 um)
    eta_open = 1.5e-6
    assert n0 - k_n * eta_open > 0 and normal_force(eta_open, 0.0, n0, d0, 1.0, 0.0, True, k3) == 0.0
    # the harmonic balance's tangents are the derivatives of the integrator's law
    eta = np.linspace(-9e-7, 9e-7, 7)
    deta = np.full(eta.size, 1e-4)
    N, dN, dNd = (np.empty(eta.size) for _ in range(3))
    normal_path(eta, deta, n0, d0, 1.0, k3, 30.0, True, N, dN, dNd)
    h = 1e-12
    fd = [
        (
            normal_force(e + h, 1e-4, n0, d0, 1.0, 30.0, True, k3)
            - normal_force(e - h, 1e-4, n0, d0, 1.0, 30.0, True, k3)
        )
        / (2 * h)
        for e in eta
    ]
    assert dN == pytest.approx(fd, rel=1e-5)


def test_damping_forms():
    f = np.array([50.0, 150.0, 3000.0])
    assert damping_ratios(f, 0.005, "modal") == pytest.approx([0.005] * 3)
    assert damping_ratios(f, 0.005, "stiffness_proportional", 50.0) == pytest.approx([0.005, 0.015, 0.3])
    assert damping_ratios(f, 0.005, "mass_proportional", 50.0) == pytest.approx([0.005, 0.005 / 3, 0.001])  # floored
    # Rayleigh, both terms equal at f_ref: 0.005 there, (1/3 + 3) / 2 x 0.005 at 150 Hz, capped at 2 far above
    assert damping_ratios(f, 0.005, "rayleigh", 50.0) == pytest.approx(
        [0.005, 0.005 * (1 / 3 + 3) / 2, 0.0025 * (1 / 60 + 60)]
    )
    assert damping_ratios([5.0e5], 0.005, "rayleigh", 50.0) == pytest.approx([2.0])
    with pytest.raises(ValueError, match="rig.true_damping.form"):
        damping_ratios(f, 0.005, "hysteretic")


@pytest.mark.slow  # one random test and one dual-sine test of a perturbed rig (small config's records)
def test_perturbed_rig_with_two_effects_runs_and_its_raw_records_carry_nothing_of_it(small_config):
    c = copy.deepcopy(small_config)
    rig = copy.deepcopy(c["rig"])
    rig["true_structure"] = PERTURBED
    rig["truth"]["normal"].update({"exponent": 1.0, "cubic_n_per_m3": 4.0e19})
    rig["true_damping"] = {"form": "stiffness_proportional", "reference_frequency_hz": 54.4}
    rig["effects"] = {"normal_contact_damping": 300.0, "viscous_friction": 300.0}
    contact = contact_parameters(c["structure"], rig)
    assert (contact.hunt_crossley, contact.viscous, contact.cubic, contact.exponent) == (300.0, 300.0, 4.0e19, 1.0)

    raw_rt, truth_rt = random_test_datasets(c["structure"], rig, c["random_test"], 1)
    _, truth_nominal = random_test_datasets(c["structure"], c["rig"], c["random_test"], 1)
    # the stiffer beam and the heavier, lever-arm-changed, clamp-compliant rig move the frequencies by per cents
    change = truth_rt["natural_frequency"].values[:3] / truth_nominal["natural_frequency"].values[:3] - 1
    assert np.all(np.abs(change) > 1e-3) and np.all(np.abs(change) < 0.1)
    zeta = truth_rt["damping_ratio"].values
    assert zeta[1] / zeta[0] == pytest.approx(
        truth_rt["natural_frequency"].values[1] / truth_rt["natural_frequency"].values[0], rel=1e-9
    )

    raw, truth = dual_sine_test(
        c["structure"], rig, c["load_cases"]["lc1"], FS, 0.005, 1, "lc1", c["structure"]["sensors"]["names"]
    )
    assert truth.attrs["control_converged"] == 1
    assert truth.attrs["normal_cubic_n_per_m3"] == 4.0e19
    for ds in (raw, raw_rt):  # a raw record holds what a real test records, nothing of the rig's truth
        assert set(ds.data_vars) == {"force", "acceleration"}
        assert list(ds["position"].values) == c["structure"]["sensors"]["positions_m"]
        text = " ".join(f"{k}={v}" for k, v in ds.attrs.items()).lower()
        for word in ("true", "young", "cubic", "damping", "effect", "lever", "clamp", "mass"):
            assert word not in text, (word, text)
