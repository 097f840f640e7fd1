import math

import numpy as np
import pytest
from contactid.analytic import beam_frequencies_hz, clamped_free_eigenvalues, clamped_pinned_eigenvalues
from contactid.beam_modes import ContactFrequencyMap, natural_frequencies
from structures import configured_structure, mass_candidate_structure


def bare_beam(**kw):
    """The beam alone: no transducers, no pin, the block decoupled (k_s = 0, g = 0, J_s = 0)."""
    base = dict(
        pin_mass=0.0,
        pin_inertia=0.0,
        force_transducer_mass=0.0,
        sensor_masses=(0.0, 0.0, 0.0),
        block_inertia=0.0,
        string_stiffness=0.0,
        gravity=0.0,
        k_t=0.0,
        k_n=0.0,
        normal_lever_arm=0.0,
        tangential_lever_arm=0.0,
        hanger_lever_arm=0.0,
        axial_inertia=True,
        n_elements=60,
    )
    base.update(kw)
    return configured_structure(**base)


def test_clamped_free_limit_matches_analytic():
    p = bare_beam()
    f = natural_frequencies(p, 4)
    exact = beam_frequencies_hz(clamped_free_eigenvalues(4), p.bending_stiffness, p.mass_per_length, p.length)
    assert np.max(np.abs(f / exact - 1)) < 1e-4


def test_clamped_pinned_limit_matches_analytic():
    p = bare_beam(k_n=1e11)
    f = natural_frequencies(p, 4)
    exact = beam_frequencies_hz(clamped_pinned_eigenvalues(4), p.bending_stiffness, p.mass_per_length, p.length)
    assert np.max(np.abs(f / exact - 1)) < 1e-4


def test_frequency_map_agrees_with_full_solution():
    p = configured_structure()
    fmap = ContactFrequencyMap(p, 3)
    assert fmap._basis is not None  # the Ritz basis (modes of K_0 and the static contact shapes)
    # over the stiffness fit's whole search box, as exact as the full eigenproblem to 1e-8
    for kt in np.logspace(5, 9, 5):
        for kn in np.logspace(5, 11, 5):
            assert fmap(kt, kn) == pytest.approx(natural_frequencies(p.with_contact(kt, kn), 3), rel=1e-8)


def test_frequency_map_keeps_its_ritz_basis_where_a_static_shape_nearly_lies_in_the_modes_span():
    """The eta static shape lies within 4e-8 of the lowest 20 modes' span: on this structure (a mass candidate's,
    transducers 7.5 % heavy) the Cholesky factor of V^T M V failed and the map solved the full eigenproblem at every
    call; Gram-Schmidt in the mass metric keeps the basis and the map exact to 1e-8."""
    p = mass_candidate_structure()
    fmap = ContactFrequencyMap(p, 3)
    assert fmap._basis is not None and fmap._basis[0].shape[1] == 22  # 20 modes and both static shapes
    for kt in np.logspace(5, 9, 5):
        for kn in np.logspace(5, 11, 5):
            assert fmap(kt, kn) == pytest.approx(natural_frequencies(p.with_contact(kt, kn), 3), rel=1e-8)


def test_stiffer_tangential_contact_raises_frequencies():
    p = configured_structure()
    f_soft = natural_frequencies(p.with_contact(1e6, 2.37e7))
    f_stiff = natural_frequencies(p.with_contact(1e8, 2.37e7))
    assert np.all(f_stiff > f_soft)
    assert math.isclose(p.axial_stiffness, p.youngs_modulus * p.area / p.length)


@pytest.mark.parametrize("scale", [0.9, 0.97, 1.05, 1.1])
def test_the_frequency_map_at_a_stiffness_scale_is_the_structure_with_that_e(scale, default_config):
    """The stiffness fit's map at scale s (K_0 + (s - 1) K_E in the structure's Ritz basis) against the full
    eigenproblem of the structure with E x s; and linear_modes.nc's scale rebuilds that structure
    (parameters.identified_structure)."""
    from contactid.parameters import identified_structure, structure_from_config

    p = configured_structure(tangential_lever_arm=0.00458)
    fmap = ContactFrequencyMap(p, 3)
    full = natural_frequencies(p.replace(youngs_modulus=scale * p.youngs_modulus).with_contact(1.43e7, 2.37e7), 3)
    np.testing.assert_allclose(fmap(1.43e7, 2.37e7, scale), full, rtol=1e-8)
    cfg = default_config["structure"]
    built = identified_structure(cfg, {"k_t": 1.43e7, "k_n": 2.37e7, "stiffness_scale": scale})
    plain = structure_from_config(cfg, 1.43e7, 2.37e7)
    assert built == plain.replace(youngs_modulus=scale * plain.youngs_modulus)
    assert identified_structure(cfg, {"k_t": 1.43e7, "k_n": 2.37e7}) == plain  # a dataset without a scale: E as given
