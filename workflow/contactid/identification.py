"""Nonlinear identification of the contact forces S(t), N(t) from a dual-sine record (Sections 4-5).

Two methods, side by side:

``paper`` (the reproduction): generalized coordinates from the linear modes (Eq. 15), a
least-squares Fourier series in K harmonics (Eq. 16) integrated analytically (Eq. 17), two real
nonlinear normal modes built from the harmonic amplitudes (Eq. 20), the Galerkin reduced model on
them (Eqs. 10-12, stiffness without the contact springs) and, at each instant, the 2x2 solve

    F_ext - M q'' - K q = [dxi/dq, -deta/dq] [S; N - N0]

(sign from the virtual work (A4) with S the force the structure exerts on the contact and N
positive in compression, eta positive when the contact opens).

``inverse`` (the working method): per-harmonic inverse identification with the identified linear
FE model. The contact forces enter as unknown inputs through their deviation from the stuck
springs, r_xi = S - k_t xi and r_eta = N_dyn + k_n eta, so the identified stuck system (with its
modal damping) is the linear operator; for each harmonic h of the test frequency the sensor
accelerations give a least-squares solve for (r_xi, r_eta); the physical motion q_h follows, and
with it xi, eta, S and N. Only what a test gives is used: force, accelerations, the linear model.
The mean (h = 0) of S, N, xi, eta is not observable from accelerometers: all outputs are
mean-removed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .beam_model import FEModel, shortening_matrix
from .beam_modes import all_modes
from .harmonics import fourier_series, periodic_grid, positive_spectrum, synthesize


class IdentificationError(ValueError):
    """The identification cannot run with these settings (for example m > j)."""


def _column_forms(q: np.ndarray, G: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Return q[:, t]^T G p[:, t] for every column t, (n_t,), through one matrix product.

    The three-operand einsum it replaces does not use BLAS: one case's contact_forces_dataset took 4.2 s instead of
    1.4 s.
    """
    return np.einsum("it,it->t", q, G @ p)


def nrmse(estimate: np.ndarray, truth: np.ndarray) -> float:
    """Return rms(error) / rms(truth), both mean-removed (the contract's NRMSE).

    Parameters
    ----------
    estimate
        The estimated signal [unit of truth], shape (n_t,) (any shape, the same as ``truth``'s), n_t samples.
    truth
        The reference signal, in any unit (N, m, m/s^2...) [unit of estimate], shape (n_t,) as ``estimate``.

    Returns
    -------
    nrmse : float
        rms of the mean-removed error over rms of the mean-removed truth [-].
    """
    e = estimate - np.mean(estimate) - (truth - np.mean(truth))
    return float(np.sqrt(np.mean(e**2)) / np.sqrt(np.mean((truth - np.mean(truth)) ** 2)))


# ----------------------------------------------------------------------------------------------
# the paper's chain
# ----------------------------------------------------------------------------------------------


def generalized_coordinates(
    phi_sensor: np.ndarray, acceleration: np.ndarray, fs: float, f0: float, n_harmonics: int
) -> tuple[np.ndarray, np.ndarray]:
    """Return the generalized accelerations p''(t) = Phi^+ w''(t) (Eq. 15) and their K harmonics (Eq. 16).

    Parameters
    ----------
    phi_sensor
        The m linear mode shapes at the j sensors, mass-normalised [kg^-0.5], shape (j, m).
    acceleration
        The sensors' accelerations [m/s^2], shape (j, n_t), n_t samples from t = 0.
    fs
        Sampling rate [Hz].
    f0
        Excitation frequency [Hz].
    n_harmonics
        Harmonics K of f0 in the Fourier series.

    Returns
    -------
    p_ddot : np.ndarray
        The generalized accelerations as measured [kg^0.5 m/s^2], shape (m, n_t).
    coefficients : np.ndarray
        Their complex harmonics c_h, h = 1..K (p'' ~ mean + sum Im(c_h e^{i h w t}), ``harmonics``)
        [kg^0.5 m/s^2], shape (m, K).

    Raises
    ------
    IdentificationError
        When m > j: fewer sensors than modes (Eq. 15 needs j >= m).
    """
    j, m = phi_sensor.shape
    if m > j:
        raise IdentificationError(
            f"m = {m} linear modes need at least as many sensors (Eq. 15: j >= m); "
            f"the record has j = {j}: lower nonlinear.n_modes or add sensors"
        )
    pdd = np.linalg.pinv(phi_sensor) @ acceleration
    return pdd, fourier_series(pdd, fs, f0, n_harmonics)


def nonlinear_mode_coefficients(p_coef: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the coefficients of the two real NNMs on the linear modes (Eq. 20) and their phase spread.

    The coefficients are the amplitudes of harmonics 1 and 3 of the generalized accelerations, signed by their phase
    relative to the dominant term; the spread is the largest phase deviation from 0 or 180 degrees among the terms of
    each frequency (the paper's check that the NNMs are real).

    Parameters
    ----------
    p_coef
        Complex harmonics h = 1..K of the m generalized accelerations (``generalized_coordinates``)
        [kg^0.5 m/s^2], shape (m, K), K >= 3.

    Returns
    -------
    coefficients : np.ndarray
        The NNMs at w and 3 w on the linear modes, each of unit norm [-], shape (2, m).
    spread : np.ndarray
        Each NNM's largest phase deviation from 0 or 180 degrees among its terms above 1 % of its largest [deg],
        shape (2,).

    Raises
    ------
    IdentificationError
        When K < 3 (the NNMs use harmonics 1 and 3).
    """
    if p_coef.shape[1] < 3:
        raise IdentificationError("the NNMs use harmonics 1 and 3: K must be at least 3")
    coef = np.empty((2, p_coef.shape[0]))
    spread = np.empty(2)
    for row, h in enumerate((1, 3)):
        c = p_coef[:, h - 1]
        ref = np.angle(c[np.argmax(np.abs(c))])
        dphi = np.angle(c * np.exp(-1j * ref))
        sign = np.where(np.abs(dphi) <= np.pi / 2, 1.0, -1.0)
        dev = np.abs(np.angle(np.exp(1j * dphi) * sign))
        significant = np.abs(c) > 0.01 * np.max(np.abs(c))
        spread[row] = float(np.degrees(np.max(dev[significant])))
        A = sign * np.abs(c)
        coef[row] = A / np.sqrt(np.sum(A**2))
    return coef, spread


def nnm_coordinates(
    psi_sensor: np.ndarray, acceleration: np.ndarray, fs: float, f0: float, n_harmonics: int
) -> tuple[np.ndarray, np.ndarray]:
    """Return the NNM coordinates and their accelerations from the sensors' accelerations.

    q'' = Psi^+ w'' at the sensors, kept to K harmonics, and q by analytic double integration (Eq. 17), on the
    record's time axis.

    Parameters
    ----------
    psi_sensor
        The NNMs at the j sensors [kg^-0.5], shape (j, n_nnm) (n_nnm = 2: the NNMs at w and 3 w).
    acceleration
        The sensors' accelerations [m/s^2], shape (j, n_t), n_t samples from t = 0.
    fs
        Sampling rate [Hz].
    f0
        Excitation frequency [Hz].
    n_harmonics
        Harmonics K of f0 kept.

    Returns
    -------
    q : np.ndarray
        NNM coordinates [kg^0.5 m], shape (n_nnm, n_t).
    q_ddot : np.ndarray
        NNM accelerations [kg^0.5 m/s^2], shape (n_nnm, n_t).
    """
    t = np.arange(acceleration.shape[1]) / fs
    coef = fourier_series(np.linalg.pinv(psi_sensor) @ acceleration, fs, f0, n_harmonics)
    return synthesize(coef, f0, t, -2), synthesize(coef, f0, t, 0)


def galerkin_contact_forces(model: FEModel, nnm: np.ndarray, q: np.ndarray, qdd: np.ndarray, force: np.ndarray) -> dict:
    """Return S(t), N(t) - N0 by the force-state mapping on the Galerkin reduced model (Eqs. 10-12).

    At each instant, the least-squares solve of

        F_ext - M q'' - K q = [dxi/dq, -deta/dq] [S; N - N0]

    with M = Psi^T M Psi, K = Psi^T K_0 Psi (no contact springs), xi with the shortening term.

    Parameters
    ----------
    model
        The identified linear FE model (its stiffness without the contact springs is used).
    nnm
        The n trial vectors (the NNMs) on the FE coordinates, mass-normalised shapes' combinations [kg^-0.5],
        shape (n_dof, n).
    q
        The NNM coordinates [kg^0.5 m], shape (n, n_t).
    qdd
        The NNM accelerations [kg^0.5 m/s^2], shape (n, n_t).
    force
        The driving force [N], shape (n_t,).

    Returns
    -------
    forces : dict
        ``S`` (friction force [N]), ``N_dyn`` (N - N0 [N]), ``xi``, ``eta`` (contact motions [m]), each of shape
        (n_t,); ``reduced_mass`` ([-], shape (n, n)), ``reduced_stiffness`` ([1/s^2], shape (n, n)) and
        ``reduced_force`` (generalized force of a unit force at the driving point [kg^-0.5], shape (n,)).
    """
    k0 = model.stiffness_without_contact
    Mr = nnm.T @ model.mass @ nnm
    Kr = nnm.T @ k0 @ nnm
    Fr = nnm.T @ model.force_vector
    G = nnm.T @ shortening_matrix(model) @ nnm
    xi_r = nnm.T @ model.xi_vector
    eta_r = nnm.T @ model.eta_vector
    lhs = np.outer(Fr, force) - Mr @ qdd - Kr @ q
    n_t = q.shape[1]
    S = np.empty(n_t)
    N = np.empty(n_t)
    for k in range(n_t):
        A = np.column_stack([xi_r - G @ q[:, k], -eta_r])
        S[k], N[k] = np.linalg.lstsq(A, lhs[:, k], rcond=None)[0][:2]
    xi = xi_r @ q - 0.5 * _column_forms(q, G, q)
    eta = eta_r @ q
    return {"S": S, "N_dyn": N, "xi": xi, "eta": eta, "reduced_mass": Mr, "reduced_stiffness": Kr, "reduced_force": Fr}


# ----------------------------------------------------------------------------------------------
# the working method: per-harmonic inverse identification
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class InverseResult:
    """Per-harmonic inverse identification's result: the contact's forces and motions in time and in harmonics.

    Time signals on the record's n_t samples (S, N_dyn, xi, eta mean-removed; the rates carry harmonics 1..K, no
    mean); complex harmonics h = 1..K in the convention of Eq. 16 (``harmonics``).

    Attributes
    ----------
    S
        Friction force S(t), mean removed [N], shape (n_t,).
    N_dyn
        Dynamic normal force N(t) - N0, mean removed [N], shape (n_t,).
    xi
        Tangential contact motion xi(t) (with the beam shortening's term), mean removed [m], shape (n_t,).
    eta
        Normal contact motion eta(t), positive when the contact opens, mean removed [m], shape (n_t,).
    xi_dot
        d xi/dt [m/s], shape (n_t,).
    eta_dot
        d eta/dt [m/s], shape (n_t,).
    S_coef
        Harmonics of S [N], shape (K,), complex.
    N_coef
        Harmonics of N_dyn [N], shape (K,), complex.
    xi_coef
        Harmonics of xi's linear part (xi_vector q, without the beam shortening's) [m], shape (K,), complex.
    eta_coef
        Harmonics of eta [m], shape (K,), complex.
    residual
        Misfit of the sensor accelerations per harmonic relative to their size (norm over the sensors) [-],
        shape (K,).
    """

    S: np.ndarray
    N_dyn: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    xi_dot: np.ndarray
    eta_dot: np.ndarray
    S_coef: np.ndarray
    N_coef: np.ndarray
    xi_coef: np.ndarray
    eta_coef: np.ndarray
    residual: np.ndarray


def period_coefficients(x_grid: np.ndarray, n_harmonics: int) -> np.ndarray:
    """Return the harmonics c_h (h = 1..K) of periodic rows sampled at M points over one period.

    x ~ mean + sum Im(c_h e^{i h w t}), with t = n / (M f0) (exact for M > 2K).

    Parameters
    ----------
    x_grid
        Periodic signals in any unit, sampled over one period along the last axis [unit of x_grid],
        shape (..., M).
    n_harmonics
        Harmonics K to return.

    Returns
    -------
    coefficients : np.ndarray
        Their complex harmonics [unit of x_grid], shape (..., K).
    """
    M = x_grid.shape[-1]
    X = positive_spectrum(x_grid, n_harmonics)
    return 2j * X / M


@dataclass(frozen=True)
class InverseHarmonics:
    """Harmonic-level result of the inverse identification (complex harmonics h = 1..K, convention of Eq. 16).

    Attributes
    ----------
    S
        Harmonics of the friction force S [N], shape (K,).
    N_dyn
        Harmonics of the dynamic normal force N - N0 [N], shape (K,).
    xi
        Harmonics of the tangential contact motion xi, with the beam shortening's harmonics [m], shape (K,).
    eta
        Harmonics of the normal contact motion eta [m], shape (K,).
    xi_dot
        Harmonics of d xi/dt [m/s], shape (K,).
    eta_dot
        Harmonics of d eta/dt [m/s], shape (K,).
    q
        Harmonics of the stuck system's FE coordinates [m] (translations) and [rad] (rotations),
        shape (n_dof, K).
    r
        Harmonics of the unknown inputs r_xi = S - k_t xi_lin and r_eta = N_dyn + k_n eta [N], shape (2, K).
    residual
        Misfit of the sensor accelerations per harmonic relative to their size (norm over the sensors) [-],
        shape (K,).
    """

    S: np.ndarray
    N_dyn: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    xi_dot: np.ndarray
    eta_dot: np.ndarray
    q: np.ndarray
    r: np.ndarray
    residual: np.ndarray


def inverse_harmonics(
    model: FEModel,
    zeta: np.ndarray,
    F_coef: np.ndarray,
    A_coef: np.ndarray,
    f0: float,
    n_iterations: int = 8,
    grid_factor: int = 4,
) -> InverseHarmonics:
    """Identify the contact forces harmonic by harmonic from the force's and the sensors' harmonics.

    The axial-force term of Eq. 1 (G q S) mixes harmonics; it is moved to the known side and updated by fixed-point
    iteration, its products evaluated on ``grid_factor`` x K points of one period (at least 4: above 3K the bins 1..K
    take no alias; benchmarks/identification_kernels.py times 4 against the 8 of before).

    Parameters
    ----------
    model
        The identified linear FE model, with its stuck contact springs k_t, k_n.
    zeta
        The damping ratio of every FE mode (``modal_damping_vector``) [-], shape (n_dof,).
    F_coef
        The force's complex harmonics h = 1..K (convention of Eq. 16) [N], shape (K,) (a longer array: its first
        K).
    A_coef
        The sensors' acceleration harmonics h = 1..K [m/s^2], shape (j, K); K is taken from it.
    f0
        Excitation frequency [Hz].
    n_iterations
        Most fixed-point iterations on the axial-force term (they stop where it changes by less than 1e-8,
        relative); 1 or less: one pass without it.
    grid_factor
        Points of the one-period grid per harmonic (grid_factor x K points), 4 or more.

    Returns
    -------
    harmonics : InverseHarmonics
        The contact's forces and motions, the coordinates, the unknown inputs and the sensor misfit per harmonic.

    Raises
    ------
    ValueError
        When ``grid_factor`` is below 4 (3K points alias).
    """
    modes = all_modes(model)
    phi = modes.shapes
    wn = 2 * np.pi * modes.frequencies_hz
    p = model.params
    w0 = 2 * np.pi * f0
    K = A_coef.shape[1]
    b_f = phi.T @ model.force_vector
    b_xi = phi.T @ model.xi_vector
    b_eta = phi.T @ model.eta_vector
    sens = model.sensor_vectors @ phi
    G = shortening_matrix(model)
    n_dof = phi.shape[0]
    # one-period grid for the nonlinear terms: a product of two K-harmonic signals has harmonics up to 2K, which M > 3K
    # points keep off the bins 1..K (no aliasing: the same harmonics to rounding as on 8K points, at half the cost)
    if grid_factor < 4:
        raise ValueError(f"inverse_harmonics: grid_factor = {grid_factor}; give 4 or more (3K points alias)")
    M = int(grid_factor) * K
    geo_coef = np.zeros((n_dof, K), dtype=complex)  # harmonics of G q S (generalized force)
    W = np.arange(1, K + 1) * w0
    g = 1.0 / (wn[:, None] ** 2 - W[None, :] ** 2 + 2j * zeta[:, None] * wn[:, None] * W[None, :])  # (modes, K)
    # the unknown inputs' transfer to the sensors per harmonic, (K, j, 2), and its pseudo-inverse
    Amat = np.stack([-(sens @ (g * b_xi[:, None])), sens @ (g * b_eta[:, None])], axis=-1).transpose(1, 0, 2)
    Apinv = np.linalg.pinv(Amat)  # (K, 2, j): the least-squares solution of each harmonic's 2 unknowns
    disp = A_coef / (-(W**2))  # sensor displacements (j, K)
    qg = None  # q on the period grid, of the latest q_coef
    for it in range(max(1, n_iterations)):
        known = g * (b_f[:, None] * F_coef[None, :K] + phi.T @ geo_coef)  # modal (modes, K)
        rhs = disp - sens @ known
        r_coef = np.einsum("kuj,jk->uk", Apinv, rhs)  # (2, K)
        q_coef = phi @ (known + g * (-b_xi[:, None] * r_coef[0] + b_eta[:, None] * r_coef[1]))
        misfit = np.einsum("kju,uk->jk", Amat, r_coef) - rhs
        residual = np.linalg.norm(misfit, axis=0) / np.maximum(np.linalg.norm(disp, axis=0), 1e-300)
        if n_iterations <= 1:
            break
        qg = periodic_grid(q_coef, f0, M)
        S_g = periodic_grid(r_coef[:1], f0, M)[0] + p.k_t * (model.xi_vector @ qg)
        new = period_coefficients((G @ qg) * S_g, K)
        change = np.linalg.norm(new - geo_coef) / max(np.linalg.norm(new), 1e-300)
        geo_coef = new
        if change < 1e-8:
            break
    if qg is None:  # a single pass: the loop stopped before the grid
        qg = periodic_grid(q_coef, f0, M)
    qdg = periodic_grid(q_coef, f0, M, 1)
    xi_lin = model.xi_vector @ q_coef
    xi = xi_lin - 0.5 * period_coefficients(_column_forms(qg, G, qg), K)
    xi_dot = period_coefficients(model.xi_vector @ qdg - _column_forms(qg, G, qdg), K)
    eta = model.eta_vector @ q_coef
    h = np.arange(1, K + 1)
    return InverseHarmonics(
        S=r_coef[0] + p.k_t * xi_lin,
        N_dyn=r_coef[1] - p.k_n * eta,
        xi=xi,
        eta=eta,
        xi_dot=xi_dot,
        eta_dot=1j * h * w0 * eta,
        q=q_coef,
        r=r_coef,
        residual=residual,
    )


def inverse_identification(
    model: FEModel,
    zeta: np.ndarray,
    force: np.ndarray,
    acceleration: np.ndarray,
    fs: float,
    f0: float,
    n_harmonics: int,
    n_iterations: int = 8,
) -> InverseResult:
    """Identify the contact forces as unknown inputs, harmonic by harmonic, with the stuck linear model.

    :func:`inverse_harmonics` on the record's K harmonics, then the time signals.

    Parameters
    ----------
    model
        The identified linear FE model, with its stuck contact springs k_t, k_n.
    zeta
        The damping ratio of every FE mode (``modal_damping_vector``) [-], shape (n_dof,).
    force
        The driving force [N], shape (n_t,), n_t samples from t = 0.
    acceleration
        The sensors' accelerations [m/s^2], shape (j, n_t).
    fs
        Sampling rate [Hz].
    f0
        Excitation frequency [Hz].
    n_harmonics
        Harmonics K of f0 identified.
    n_iterations
        Most fixed-point iterations on the axial-force term (``inverse_harmonics``).

    Returns
    -------
    result : InverseResult
        The contact's forces and motions on the record's time axis and their harmonics, and the sensor misfit.
    """
    p = model.params
    K = n_harmonics
    A_coef = fourier_series(acceleration, fs, f0, K)  # (j, K)
    F_coef = fourier_series(force, fs, f0, K)[0]  # (K,)
    res = inverse_harmonics(model, zeta, F_coef, A_coef, f0, n_iterations)
    q_coef, r_coef = res.q, res.r
    G = shortening_matrix(model)
    t = np.arange(acceleration.shape[1]) / fs
    q = synthesize(q_coef, f0, t, 0)  # (n_dof, n_t)
    qd = synthesize(q_coef, f0, t, 1)
    xi = model.xi_vector @ q - 0.5 * _column_forms(q, G, q)
    xi_lin = model.xi_vector @ q
    eta = model.eta_vector @ q
    r = synthesize(r_coef, f0, t, 0)
    S = r[0] + p.k_t * xi_lin
    N_dyn = r[1] - p.k_n * eta
    xi_dot = model.xi_vector @ qd - _column_forms(q, G, qd)
    eta_dot = model.eta_vector @ qd
    return InverseResult(
        S - S.mean(),
        N_dyn - N_dyn.mean(),
        xi - xi.mean(),
        eta - eta.mean(),
        xi_dot,
        eta_dot,
        res.S,
        res.N_dyn,
        model.xi_vector @ q_coef,
        res.eta,
        res.residual,
    )
