"""Known-answer tests of the nonlinear identification (both methods)."""

import numpy as np
import pytest
from contactid.beam_model import assemble, shortening_matrix
from contactid.beam_modes import all_modes, structural_modes
from contactid.contact_laws import NormalLaw
from contactid.identification import (
    IdentificationError,
    galerkin_contact_forces,
    generalized_coordinates,
    inverse_identification,
    nonlinear_mode_coefficients,
    nrmse,
)
from contactid.rig.nonlinear import ContactParameters, reduced_model
from contactid.rig.simulator import DualSineSimulator
from structures import configured_structure, dual_sine_harmonics

P = configured_structure(tangential_lever_arm=0.00458, youngs_modulus=2.164e11, k_t=1.4276e7, k_n=2.37e7, n_elements=24)


def test_paper_algebra_returns_the_truth_on_an_exact_basis():
    """When the motion lies exactly in the trial basis (the rig's own Ritz basis, undamped),
    the Galerkin force-state mapping of Eqs. 10-12 returns the true S and N - N0."""
    model = assemble(P)
    red = reduced_model(model, 6)
    law = NormalLaw(70.0, P.k_n, 1.5)
    contact = ContactParameters((3.857e7, 2.547e5, 1e4, 0.284, 0.397), 70.0, law.static_approach, 1.5)
    sim = DualSineSimulator(red, contact, np.zeros(red.omega.size), 1.0 / 81920)
    w = 2 * np.pi * 54.4
    sim.start_from_linear(4.0, 1.0, w)
    sim.run(4.0, 1.0, w, 20000)
    out = sim.run(4.0, 1.0, w, 4000, store_from=0)
    g = galerkin_contact_forces(model, red.basis, out["z"].T, out["a"].T, out["f"])
    assert np.max(np.abs(g["S"] - out["S"])) < 1e-6 * np.max(np.abs(out["S"]))
    assert np.max(np.abs(g["N_dyn"] - (out["N"] - 70.0))) < 1e-6 * np.ptp(out["N"])
    assert np.allclose(g["xi"], out["xi"], rtol=0, atol=1e-9 * np.ptp(out["xi"]))


def linear_record(model, zeta, F1, F3, f0, fs, n):
    """Sensor accelerations of the stuck linear model under a dual sine, exactly (frequency domain)."""
    modes = all_modes(model)
    wn = 2 * np.pi * modes.frequencies_hz
    t = np.arange(n) / fs
    acc = np.zeros((model.sensor_vectors.shape[0], n))
    q = np.zeros((model.n_dof, n))
    force = np.zeros(n)
    for F, h in ((F1, 1), (F3, 3)):
        W = 2 * np.pi * f0 * h
        modal = (modes.shapes.T @ model.force_vector) * F / (wn**2 - W**2 + 2j * zeta * wn * W)
        x = modes.shapes @ modal
        q += np.imag(np.outer(x, np.exp(1j * W * t)))
        acc += np.imag(np.outer(model.sensor_vectors @ x * -(W**2), np.exp(1j * W * t)))
        force += F * np.sin(W * t)
    return force, acc, q


def test_inverse_method_on_linear_data_returns_stuck_spring_force():
    """A stuck (linear) contact: S = k_t (a w'(L) + u) exactly, N - N0 = -k_n eta."""
    model = assemble(P)
    zeta = np.full(all_modes(model).frequencies_hz.size, 0.005)
    fs, f0, n = 5120.0, 5120.0 * 174 / 16384, 16384
    force, acc, q = linear_record(model, zeta, 0.3, 0.05, f0, fs, n)
    res = inverse_identification(model, zeta, force, acc, fs, f0, 5, n_iterations=1)
    xi_lin = model.xi_vector @ q
    S_expected = P.k_t * (xi_lin - xi_lin.mean())
    assert nrmse(res.S, S_expected) < 1e-6
    eta = model.eta_vector @ q
    assert nrmse(res.N_dyn, -P.k_n * (eta - eta.mean())) < 1e-6
    G = shortening_matrix(model)
    xi = xi_lin - 0.5 * np.einsum("it,ij,jt->t", q, G, q)  # Eq. 9 with the beam shortening
    assert nrmse(res.xi, xi) < 1e-6


def test_paper_chain_refuses_more_modes_than_sensors():
    phi_s = np.random.default_rng(0).standard_normal((2, 3))
    with pytest.raises(IdentificationError, match=r"m = 3 linear modes need at least as many sensors .* j = 2"):
        generalized_coordinates(phi_s, np.zeros((2, 100)), 5120.0, 54.0, 5)


def test_real_nnms_and_phase_spread():
    """Terms in phase (or anti-phase) give a real NNM with zero spread; a 30 degree lag is flagged."""
    c = np.array(
        [
            [2.0 * np.exp(1j * 0.4), 0, 1.0 * np.exp(1j * 0.4)],
            [-0.5 * np.exp(1j * 0.4), 0, 3.0 * np.exp(1j * (0.4 + np.pi / 6))],
            [0.0 + 1e-9, 0, 0.1 * np.exp(1j * 0.4)],
        ]
    )
    coef, spread = nonlinear_mode_coefficients(c)
    assert spread[0] == pytest.approx(0.0, abs=1e-9)
    assert coef[0] == pytest.approx(np.array([2.0, -0.5, 0.0]) / np.sqrt(4.25), abs=1e-9)
    assert spread[1] == pytest.approx(30.0, abs=1e-6)


def test_structural_modes_used_by_the_chain_are_reproducible():
    m = assemble(P)
    a = structural_modes(m, 3).shapes
    b = structural_modes(assemble(P), 3).shapes
    assert np.array_equal(a, b)


def test_the_nonlinear_terms_grid_of_4k_points_gives_the_harmonics_of_8k():
    """The inverse identification's axial-force term and shortening are products of two K-harmonic signals (up to 2K
    harmonics): on 4K points (the default) the bins 1..K take no alias, and the result equals 8K points' to rounding;
    3K points alias and are refused."""
    from contactid.identification import inverse_harmonics
    from contactid.modal_damping import modal_damping_vector

    model = assemble(configured_structure())
    zeta = modal_damping_vector(model, np.array([0.004, 0.003, 0.002]))
    F, A = dual_sine_harmonics(3)
    a = inverse_harmonics(model, zeta, F, A, 54.38)
    b = inverse_harmonics(model, zeta, F, A, 54.38, grid_factor=8)
    for k in ("S", "N_dyn", "xi", "eta", "xi_dot", "q"):
        x, y = getattr(a, k), getattr(b, k)
        assert np.linalg.norm(x - y) <= 1e-12 * np.linalg.norm(y), k
    # the shortening matters here: without it (G = 0) xi would be xi_lin
    assert np.linalg.norm(a.xi - model.xi_vector @ a.q) > 1e-6 * np.linalg.norm(a.xi)
    with pytest.raises(ValueError, match="grid_factor = 3"):
        inverse_harmonics(model, zeta, F, A, 54.38, grid_factor=3)
