"""Finite-element model of the test structure (Sections 2-4, Appendix A).

Euler-Bernoulli beam with Hermite cubic elements, clamped at x = 0 (optionally
through a rotational spring), with the discrete coordinates of the paper:
u (axial tip motion, spring k_b = EA/L), y_s (stretch of the string k_s) and
theta_s (pendulum angle of the hanging block). The mass and stiffness matrices
follow the energies (A2)-(A3); transducers are point masses at their nodes.

Contact kinematics (linear parts of Eqs. 8-9):
    eta = w(L) + r_n w'(L)            (Eq. 8; positive when the contact opens)
    xi  = u + a w'(L)                 (Eq. 9 without the shortening term)
with r_n the normal lever arm (the paper's r) and a the tangential lever arm
(the paper's r; see ``config/README.md`` for why it is a separate value).

The linear contact springs of Eq. (13) enter as k_t xi^2/2 and k_n eta^2/2 in
the potential energy, so that S = k_t xi and the dynamic normal force is
N_dyn = -k_n eta (compression positive: N = N0 - k_n eta). Eq. (13) of the
paper prints N = k_n eta; the sign follows from the virtual work (A4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from .parameters import StructureParameters


@dataclass(frozen=True)
class FEModel:
    """Assembled linear finite-element model of the structure.

    Degrees of freedom q: the beam's deflections w [m] and slopes w' [rad] at the nodes (those the clamp fixes left
    out), then u, y_s [m] and theta_s [rad]. The matrices and vectors below are in the mixed units these dofs give.

    Attributes
    ----------
    nodes
        Beam node positions [m], node 0 at the clamp, shape (n_nodes,).
    mass
        Mass matrix [kg] (kg m and kg m^2 where slopes and theta_s enter), shape (n_dof, n_dof).
    stiffness
        Stiffness matrix [N/m] (N and N m/rad where slopes and theta_s enter), with the linear contact springs of
        Eq. (13), shape (n_dof, n_dof).
    w_dof
        Dof index of w at each node [-] (-1 where clamped), shape (n_nodes,).
    theta_dof
        Dof index of w' at each node [-] (-1 where clamped), shape (n_nodes,).
    u_dof
        Dof index of the axial tip motion u.
    ys_dof
        Dof index of the string's stretch y_s.
    thetas_dof
        Dof index of the block's pendulum angle theta_s.
    xi_vector
        Row vector with xi = xi_vector @ q (Eq. 9, linear part) [-] (its entry on the tip slope is the lever arm a
        [m]), shape (n_dof,).
    eta_vector
        Row vector with eta = eta_vector @ q (Eq. 8) [-] (its entry on the tip slope is the lever arm r [m]),
        shape (n_dof,).
    force_vector
        Generalized force of a unit force at d_p [-], shape (n_dof,).
    sensor_vectors
        Rows with w(x_s) = sensor_vectors @ q at the sensors [-], shape (n_sensors, n_dof).
    block_lateral_vector
        Row vector of the block's absolute lateral displacement (eta - y_s) [-], shape (n_dof,).
    block_axial_vector
        Row vector of the block's absolute axial displacement (hanging point + l_s theta_s) [-] (lever arms [m] on
        the tip slope and theta_s), shape (n_dof,).
    params
        The parameters it was built from.
    """

    nodes: np.ndarray
    mass: np.ndarray
    stiffness: np.ndarray
    w_dof: np.ndarray
    theta_dof: np.ndarray
    u_dof: int
    ys_dof: int
    thetas_dof: int
    xi_vector: np.ndarray
    eta_vector: np.ndarray
    force_vector: np.ndarray
    sensor_vectors: np.ndarray
    block_lateral_vector: np.ndarray
    block_axial_vector: np.ndarray
    params: StructureParameters

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom of the assembled model."""
        return self.mass.shape[0]

    @property
    def contact_stiffness_matrix(self) -> np.ndarray:
        """Stiffness matrix of the linear contact springs, k_t xi xi^T + k_n eta eta^T.

        Returns
        -------
        contact_stiffness_matrix : np.ndarray
            Contact springs' stiffness matrix [N/m] (mixed units as ``stiffness``), shape (n_dof, n_dof).
        """
        p = self.params
        return p.k_t * np.outer(self.xi_vector, self.xi_vector) + p.k_n * np.outer(self.eta_vector, self.eta_vector)

    @property
    def stiffness_without_contact(self) -> np.ndarray:
        """Stiffness matrix with the contact springs removed.

        Eq. (12)'s K when S and N are the whole contact forces.

        Returns
        -------
        stiffness_without_contact : np.ndarray
            Stiffness matrix without the contact springs [N/m] (mixed units as ``stiffness``), shape (n_dof, n_dof).
        """
        return self.stiffness - self.contact_stiffness_matrix


def mesh_nodes(length: float, key_points: Iterable[float], n_elements: int) -> np.ndarray:
    """Return node positions with a node at every key point and about ``n_elements`` elements of near-equal size.

    Parameters
    ----------
    length
        Beam length [m].
    key_points
        Positions that must be nodes (sensors, excitation) [m], measured from the clamp.
    n_elements
        Target number of elements over the whole length.

    Returns
    -------
    nodes : np.ndarray
        Node positions [m], ascending from 0 to ``length``, shape (n_nodes,).
    """
    pts = sorted({0.0, float(length), *(float(x) for x in key_points)})
    h_target = length / max(int(n_elements), 1)
    nodes = [0.0]
    for a, b in zip(pts[:-1], pts[1:]):
        if b - a <= 1e-12:
            continue
        n = max(1, int(math.ceil((b - a) / h_target - 1e-9)))
        nodes.extend(np.linspace(a, b, n + 1)[1:].tolist())
    return np.asarray(nodes)


def _element_matrices(EI: float, rhoA: float, le):
    """Return Hermite beam element stiffness and consistent mass matrices.

    In N/m and kg (mixed units), of elements of length ``le`` (m; a scalar: (4, 4) each, an array of n: (n, 4, 4)).
    """
    le = np.asarray(le, dtype=float)
    one, z = np.ones_like(le), le
    k = (EI / le**3)[..., None, None] * np.stack(
        [
            np.stack([12 * one, 6 * z, -12 * one, 6 * z], -1),
            np.stack([6 * z, 4 * z**2, -6 * z, 2 * z**2], -1),
            np.stack([-12 * one, -6 * z, 12 * one, -6 * z], -1),
            np.stack([6 * z, 2 * z**2, -6 * z, 4 * z**2], -1),
        ],
        -2,
    )
    m = (rhoA * le / 420.0)[..., None, None] * np.stack(
        [
            np.stack([156 * one, 22 * z, 54 * one, -13 * z], -1),
            np.stack([22 * z, 4 * z**2, 13 * z, -3 * z**2], -1),
            np.stack([54 * one, 13 * z, 156 * one, -22 * z], -1),
            np.stack([-13 * z, -3 * z**2, -22 * z, 4 * z**2], -1),
        ],
        -2,
    )
    return k, m


def _element_scatter(w_dof: np.ndarray, theta_dof: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return where the elements' matrix entries add into the global matrix.

    (rows, cols, sel): where the entries of the elements' (n_el, 4, 4) matrices, flattened and taken at ``sel``, add
    into the global matrix, element by element and row by row (clamped dofs, index -1, left out).
    """
    d = np.stack([w_dof[:-1], theta_dof[:-1], w_dof[1:], theta_dof[1:]], axis=1)  # (n_el, 4)
    rows = np.broadcast_to(d[:, :, None], d.shape + (4,)).reshape(-1)
    cols = np.broadcast_to(d[:, None, :], d.shape + (4,)).reshape(-1)
    sel = np.flatnonzero((rows >= 0) & (cols >= 0))
    return rows[sel], cols[sel], sel


def _element_shortening(le):
    """Return int N'^T N' dx of Hermite elements (the geometric stiffness of a unit axial tension).

    In 1/m; of elements of length ``le`` (m; a scalar: (4, 4), an array of n: (n, 4, 4)).
    """
    z = np.asarray(le, dtype=float)
    one = np.ones_like(z)
    return (1.0 / (30.0 * z))[..., None, None] * np.stack(
        [
            np.stack([36 * one, 3 * z, -36 * one, 3 * z], -1),
            np.stack([3 * z, 4 * z**2, -3 * z, -(z**2)], -1),
            np.stack([-36 * one, -3 * z, 36 * one, -3 * z], -1),
            np.stack([3 * z, -(z**2), -3 * z, 4 * z**2], -1),
        ],
        -2,
    )


def shortening_matrix(model: "FEModel") -> np.ndarray:
    """Return G with int_0^L w'^2 dx = q^T G q, times the structure's ``shortening_scale``.

    The beam shortening of Eq. (9) is -q^T G q / 2, times the structure's ``shortening_scale`` (1: Eq. 9 as printed;
    0: linear kinematics, G = 0). The elements' matrices are scattered as ``assemble`` scatters its own (the sums of an
    element-by-element loop, bit for bit).

    Parameters
    ----------
    model
        The assembled model.

    Returns
    -------
    G : np.ndarray
        Shortening matrix [1/m] between deflection dofs (mixed units: [-] between a deflection and a slope, [m]
        between slopes), shape (n_dof, n_dof).
    """
    G = np.zeros((model.n_dof, model.n_dof))
    rows, cols, sel = _element_scatter(model.w_dof, model.theta_dof)
    np.add.at(G, (rows, cols), _element_shortening(np.diff(model.nodes)).reshape(-1)[sel])
    return G * model.params.shortening_scale


def _node_index(nodes: np.ndarray, x: float) -> int:
    i = int(np.argmin(np.abs(nodes - x)))
    if abs(nodes[i] - x) > 1e-9:
        raise ValueError(f"no FE node at x = {x} m")
    return i


def assemble(params: StructureParameters) -> FEModel:
    """Assemble the mass and stiffness matrices from the energies (A2)-(A3).

    Parameters
    ----------
    params
        The structure.

    Returns
    -------
    model : FEModel
        The assembled model, with the linear contact springs of Eq. (13) in its stiffness.

    Raises
    ------
    ValueError
        When a sensor or the excitation position lies outside the beam (0, L].
    """
    p = params
    key = [*p.sensor_positions, p.excitation_position]
    for x in key:
        if not 0.0 < x <= p.length:
            raise ValueError(f"position {x} m is outside the beam (0, {p.length}] m")
    nodes = mesh_nodes(p.length, key, p.n_elements)
    n_nodes = len(nodes)
    clamp_free_rotation = math.isfinite(p.clamp_rotational_stiffness)

    w_dof = -np.ones(n_nodes, dtype=int)
    theta_dof = -np.ones(n_nodes, dtype=int)
    idx = 0
    if clamp_free_rotation:
        theta_dof[0] = idx
        idx += 1
    for i in range(1, n_nodes):
        w_dof[i] = idx
        theta_dof[i] = idx + 1
        idx += 2
    u_dof, ys_dof, thetas_dof = idx, idx + 1, idx + 2
    n = idx + 3

    M = np.zeros((n, n))
    K = np.zeros((n, n))
    # the elements' matrices scattered in one call, in the order an element-by-element loop adds them (the same sums,
    # bit for bit): model updating assembles the structure a few hundred times per data set (1.5 -> 0.3 ms each)
    rows, cols, sel = _element_scatter(w_dof, theta_dof)
    ke, me = _element_matrices(p.bending_stiffness, p.mass_per_length, np.diff(nodes))
    np.add.at(K, (rows, cols), ke.reshape(-1)[sel])
    np.add.at(M, (rows, cols), me.reshape(-1)[sel])
    if clamp_free_rotation:
        K[theta_dof[0], theta_dof[0]] += p.clamp_rotational_stiffness

    # transducers as point masses
    for x, m in zip(p.sensor_positions, p.sensor_masses):
        M[w_dof[_node_index(nodes, x)], w_dof[_node_index(nodes, x)]] += m
    i_dp = _node_index(nodes, p.excitation_position)
    M[w_dof[i_dp], w_dof[i_dp]] += p.force_transducer_mass

    iL = n_nodes - 1
    wL, tL = w_dof[iL], theta_dof[iL]

    def unit(*pairs):
        v = np.zeros(n)
        for d, c in pairs:
            v[d] += c
        return v

    eta = unit((wL, 1.0), (tL, p.normal_lever_arm))  # Eq. 8
    xi = unit((u_dof, 1.0), (tL, p.tangential_lever_arm))  # Eq. 9, linear part

    # pin: lateral translation of its centre and rotation (A2); axial inertia optional
    M += p.pin_mass * np.outer(eta, eta)
    M[tL, tL] += p.pin_inertia
    # block: lateral (eta - y_s) and axial (hanging point + l_s theta_s) translations (A2)
    lateral = eta - unit((ys_dof, 1.0))
    axial = unit((u_dof, 1.0), (tL, -p.hanger_lever_arm), (thetas_dof, p.string_length))
    M += p.block_mass * (np.outer(lateral, lateral) + np.outer(axial, axial))
    M[thetas_dof, thetas_dof] += p.block_inertia
    if p.axial_inertia:
        M[u_dof, u_dof] += p.mass_per_length * p.length / 3.0 + p.pin_mass

    # potential energy (A3) and the linear contact springs (Eq. 13)
    K[u_dof, u_dof] += p.axial_stiffness
    K[ys_dof, ys_dof] += p.string_stiffness
    K[thetas_dof, thetas_dof] += p.block_mass * p.gravity * p.string_length
    K += p.k_t * np.outer(xi, xi) + p.k_n * np.outer(eta, eta)

    force = unit((w_dof[i_dp], 1.0))
    sensors = np.array([unit((w_dof[_node_index(nodes, x)], 1.0)) for x in p.sensor_positions])
    return FEModel(nodes, M, K, w_dof, theta_dof, u_dof, ys_dof, thetas_dof, xi, eta, force, sensors, lateral, axial, p)


def shape_on_grid(model: FEModel, q: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the lateral deflection w(x) and slope w'(x) of dof vector(s) ``q``.

    Evaluated with the Hermite shape functions of the element holding each x.

    Parameters
    ----------
    model
        The assembled model.
    q
        Dof vector(s): displacements [m] (slopes in rad), or mass-normalised mode shapes [kg^-0.5]; shape (n_dof,)
        or (n_dof, n_vectors).
    x
        Positions along the beam, measured from the clamp [m], shape (n_x,).

    Returns
    -------
    w : np.ndarray
        Deflection at ``x`` [unit of q] (m for displacements), shape (n_x,) or (n_x, n_vectors) as ``q``.
    slope : np.ndarray
        Slope w' at ``x`` [rad] for displacements ([unit of q] per m in general), shape (n_x,) or (n_x, n_vectors).
    """
    q = np.asarray(q)
    squeeze = q.ndim == 1
    if squeeze:
        q = q[:, None]
    nodes = model.nodes

    def nodal(dofs):
        out = np.zeros((len(nodes), q.shape[1]))
        ok = dofs >= 0
        out[ok] = q[dofs[ok]]
        return out

    W, T = nodal(model.w_dof), nodal(model.theta_dof)
    x = np.asarray(x, dtype=float)
    e = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, len(nodes) - 2)
    le = nodes[e + 1] - nodes[e]
    s = (x - nodes[e]) / le
    N1, N2 = 1 - 3 * s**2 + 2 * s**3, le * (s - 2 * s**2 + s**3)
    N3, N4 = 3 * s**2 - 2 * s**3, le * (-(s**2) + s**3)
    d1, d2 = (-6 * s + 6 * s**2) / le, 1 - 4 * s + 3 * s**2
    d3, d4 = (6 * s - 6 * s**2) / le, -2 * s + 3 * s**2
    w = N1[:, None] * W[e] + N2[:, None] * T[e] + N3[:, None] * W[e + 1] + N4[:, None] * T[e + 1]
    dw = d1[:, None] * W[e] + d2[:, None] * T[e] + d3[:, None] * W[e + 1] + d4[:, None] * T[e + 1]
    if squeeze:
        return w[:, 0], dw[:, 0]
    return w, dw
