import math

import numpy as np
import pytest
from contactid.analytic import clamped_free_eigenvalues, clamped_pinned_eigenvalues
from contactid.beam_model import assemble, shape_on_grid
from contactid.beam_modes import structural_modes
from structures import configured_structure


def test_analytic_eigenvalues_known_values():
    assert clamped_free_eigenvalues(2) == pytest.approx([1.875104069, 4.694091133], rel=1e-9)
    assert clamped_pinned_eigenvalues(2) == pytest.approx([3.926602312, 7.068582745], rel=1e-9)


def test_modes_are_mass_normalised_and_structural():
    m = assemble(configured_structure())
    modes = structural_modes(m, 3)
    gen_mass = modes.shapes.T @ m.mass @ modes.shapes
    assert np.allclose(gen_mass, np.eye(3), atol=1e-9)
    assert np.all(modes.block_energy_fraction < 0.01)
    assert 40 < modes.frequencies_hz[0] < 70  # the suspension modes (about 1 and 8.5 Hz) are left out


def test_contact_springs_follow_the_energies():
    """N_dyn = -k_n eta: the contact stiffness matrix is k_t xi xi^T + k_n eta eta^T (positive semi-definite),
    and a static tip deflection pushing the contact closed (eta < 0) raises the compression."""
    p = configured_structure()
    m = assemble(p)
    kc = m.contact_stiffness_matrix
    assert np.min(np.linalg.eigvalsh(kc)) > -1e-6 * np.max(np.abs(kc))
    q = np.zeros(m.n_dof)
    q[m.w_dof[-1]] = -1e-6  # tip pushed into the support
    eta = m.eta_vector @ q
    n_dyn = -p.k_n * eta
    assert eta < 0 and n_dyn > 0
    # the generalized contact force equals the gradient of the spring energy
    energy_grad = kc @ q
    assert np.allclose(energy_grad, p.k_n * eta * m.eta_vector + p.k_t * (m.xi_vector @ q) * m.xi_vector)


def test_shape_on_grid_interpolates_nodes():
    m = assemble(configured_structure())
    modes = structural_modes(m, 2)
    w, dw = shape_on_grid(m, modes.shapes[:, 0], m.nodes)
    assert w[0] == 0 and dw[0] == 0
    assert np.allclose(w[1:], modes.shapes[m.w_dof[1:], 0])
    assert np.allclose(dw[1:], modes.shapes[m.theta_dof[1:], 0])


def test_positions_outside_beam_are_refused():
    with pytest.raises(ValueError, match="outside the beam"):
        assemble(configured_structure(sensor_positions=(0.55, 0.3, 0.7)))


def test_the_shortening_scales_with_the_structures_shortening_scale():
    """G (int w'^2 dx = q^T G q) times shortening_scale: 0 gives linear kinematics, and a shape's shortening is
    the analytic one (w = x^2: int_0^L 4 x^2 dx = 4 L^3 / 3, held exactly by the cubic elements)."""
    from contactid.beam_model import shortening_matrix

    p = configured_structure()
    m = assemble(p)
    q = np.zeros(m.n_dof)
    x = m.nodes
    q[m.w_dof[m.w_dof >= 0]] = (x**2)[m.w_dof >= 0]
    q[m.theta_dof[m.theta_dof >= 0]] = (2 * x)[m.theta_dof >= 0]
    assert q @ shortening_matrix(m) @ q == pytest.approx(4 * p.length**3 / 3, rel=1e-12)
    half = assemble(p.replace(shortening_scale=0.5))
    assert np.array_equal(shortening_matrix(half), 0.5 * shortening_matrix(m))
    assert not np.any(shortening_matrix(assemble(p.replace(shortening_scale=0.0))))


@pytest.mark.parametrize("clamp", [math.inf, 3e4])
def test_the_scattered_assembly_adds_what_an_element_loop_adds(clamp):
    # the elements' matrices are scattered in one call (np.add.at): the same sums in the same order as adding them
    # element by element, so the structure (and every frequency the chain reports) is the same bit for bit
    from contactid.beam_model import _element_matrices

    p = configured_structure(clamp_rotational_stiffness=clamp)
    m = assemble(p)
    K = np.zeros_like(m.stiffness)
    M = np.zeros_like(m.mass)
    for e in range(m.nodes.size - 1):
        ke, me = _element_matrices(p.bending_stiffness, p.mass_per_length, m.nodes[e + 1] - m.nodes[e])
        dofs = [m.w_dof[e], m.theta_dof[e], m.w_dof[e + 1], m.theta_dof[e + 1]]
        for a, da in enumerate(dofs):
            for b, db in enumerate(dofs):
                if da >= 0 and db >= 0:
                    K[da, db] += ke[a, b]
                    M[da, db] += me[a, b]
    # the beam's part: the whole matrices less what assemble adds outside the elements (the contact springs, the
    # clamp's spring, the block's and the transducers' masses) are compared where only the elements contribute
    interior = [d for d in m.w_dof[1:-1].tolist() + m.theta_dof[1:-1].tolist() if d >= 0]
    sensors = {int(np.flatnonzero(v)[0]) for v in m.sensor_vectors} | {int(np.flatnonzero(m.force_vector)[0])}
    beam_only = [d for d in interior if d not in sensors]
    ix = np.ix_(beam_only, beam_only)
    assert np.array_equal(m.stiffness[ix], K[ix]) and np.array_equal(m.mass[ix], M[ix])
    # and an element's matrices as the textbook has them (EI/l^3 [12 6l ...], rho A l / 420 [156 22l ...])
    ke, me = _element_matrices(2.0, 3.0, 0.5)
    assert ke[0, 0] == 2.0 / 0.125 * 12 and ke[1, 3] == 2.0 / 0.125 * 2 * 0.25
    assert me[0, 2] == 3.0 * 0.5 / 420 * 54 and me[3, 1] == 3.0 * 0.5 / 420 * -3 * 0.25


def test_the_scattered_shortening_matrix_adds_what_an_element_loop_adds():
    # G (int w'^2 dx = q^T G q) scattered in one call: the sums of the element-by-element loop, bit for bit; and its
    # form on a beam's static deflection (w'^2 integrated exactly for a cubic)
    from contactid.beam_model import _element_shortening, shortening_matrix

    m = assemble(configured_structure())
    G = np.zeros((m.n_dof, m.n_dof))
    for e in range(m.nodes.size - 1):
        ge = _element_shortening(m.nodes[e + 1] - m.nodes[e])
        dofs = [m.w_dof[e], m.theta_dof[e], m.w_dof[e + 1], m.theta_dof[e + 1]]
        for a, da in enumerate(dofs):
            for b, db in enumerate(dofs):
                if da >= 0 and db >= 0:
                    G[da, db] += ge[a, b]
    assert np.array_equal(shortening_matrix(m), G * m.params.shortening_scale)
    # w = x^2 (w' = 2x) is exact in Hermite cubics: int_0^L 4 x^2 dx = 4 L^3 / 3
    q = np.zeros(m.n_dof)
    ok = m.w_dof >= 0
    q[m.w_dof[ok]] = m.nodes[ok] ** 2
    q[m.theta_dof[m.theta_dof >= 0]] = 2 * m.nodes[m.theta_dof >= 0]
    L = m.nodes[-1]
    assert q @ G @ q == pytest.approx(4 * L**3 / 3, rel=1e-12)
