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

from .beam_model import FEModel, all_modes, shortening_matrix, structural_modes
from .signals import harmonic_content


class IdentificationError(ValueError):
    """The identification cannot run with these settings (for example m > j)."""


def fourier_series(signals: np.ndarray, fs: float, f0: float, n_harmonics: int) -> np.ndarray:
    """Complex harmonic amplitudes c_h (h = 1..K) of each row, signal ~ mean + sum Im(c_h e^{i h w t}) (Eq. 16)."""
    h = np.arange(1, n_harmonics + 1)
    return np.array([harmonic_content(x, fs, f0, h) for x in np.atleast_2d(signals)])


def synthesize(coef: np.ndarray, f0: float, t: np.ndarray, derivative: int = 0) -> np.ndarray:
    """Time signals sum_h Im(c_h (i h w)^d e^{i h w t}) of coefficients (rows, K); d = -2 integrates
    twice analytically (Eq. 17)."""
    coef = np.atleast_2d(coef)
    h = np.arange(1, coef.shape[1] + 1)
    w = 2 * np.pi * f0
    factor = (1j * h * w) ** derivative
    return np.imag((coef * factor) @ np.exp(1j * np.outer(h * w, t)))


def nrmse(estimate: np.ndarray, truth: np.ndarray) -> float:
    """rms(error) / rms(truth), both mean-removed (the contract's NRMSE)."""
    e = estimate - np.mean(estimate) - (truth - np.mean(truth))
    return float(np.sqrt(np.mean(e**2)) / np.sqrt(np.mean((truth - np.mean(truth)) ** 2)))


# ----------------------------------------------------------------------------------------------
# the paper's chain
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PaperChainResult:
    """Outputs of the paper's chain (SI units). p_coef: (m, K) harmonics of p''_i; nnm: (n_dof, 2)
    NNM vectors for w and 3w; phase_spread_deg: (2,) largest phase difference between the terms of
    the same frequency (Eq. 18); q, qdd: (2, n_t) NNM coordinates; reconstruction: driving-point
    acceleration from the NNM expansion (Fig. 5); S, N_dyn, xi, eta: (n_t,) mean-removed;
    reduced_mass, reduced_stiffness: (2, 2)."""

    p_coef: np.ndarray
    nnm: np.ndarray
    phase_spread_deg: np.ndarray
    q: np.ndarray
    qdd: np.ndarray
    reconstruction: np.ndarray
    S: np.ndarray
    N_dyn: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    reduced_mass: np.ndarray
    reduced_stiffness: np.ndarray
    complex_modes: bool


def paper_chain(model: FEModel, n_modes: int, force: np.ndarray, acceleration: np.ndarray, fs: float, f0: float,
                n_harmonics: int, drive_index: int, phase_limit_deg: float = 10.0) -> PaperChainResult:
    """The paper's NNM chain on one record (Eqs. 15-20, 10-12)."""
    j = acceleration.shape[0]
    if n_modes > j:
        raise IdentificationError(f"m = {n_modes} linear modes need at least as many sensors (Eq. 15: j >= m); "
                                  f"the record has j = {j}: lower nonlinear.n_modes or add sensors")
    if n_harmonics < 3:
        raise IdentificationError("the paper's chain needs K >= 3 harmonics (the NNMs use harmonics 1 and 3)")
    modes = structural_modes(model, n_modes)
    phi = modes.shapes  # (n_dof, m), mass-normalised
    Phi_s = model.sensor_vectors @ phi  # (j, m)
    t = np.arange(acceleration.shape[1]) / fs
    pdd = np.linalg.pinv(Phi_s) @ acceleration  # Eq. 15
    p_coef = fourier_series(pdd, fs, f0, n_harmonics)  # Eq. 16, (m, K)
    # Eq. 20: real NNMs from the amplitudes of harmonics 1 and 3, signed by phase
    nnm = np.empty((phi.shape[0], 2))
    spread = np.empty(2)
    for col, h in enumerate((1, 3)):
        c = p_coef[:, h - 1]
        ref = np.angle(c[np.argmax(np.abs(c))])
        dphi = np.angle(c * np.exp(-1j * ref))  # phase relative to the dominant term, in (-pi, pi]
        sign = np.where(np.abs(dphi) <= np.pi / 2, 1.0, -1.0)
        dev = np.abs(np.angle(np.exp(1j * dphi) * sign))  # distance from 0 or 180 degrees
        weights = np.abs(c) / np.max(np.abs(c))
        spread[col] = np.degrees(np.max(dev[weights > 0.01])) if np.any(weights > 0.01) else 0.0
        A = sign * np.abs(c)
        nnm[:, col] = phi @ A / np.sqrt(np.sum(A**2))
    # NNM coordinates: q'' = Psi^+ w'' at the sensors, K harmonics, analytic integration
    Psi_s = model.sensor_vectors @ nnm
    qdd_raw = np.linalg.pinv(Psi_s) @ acceleration
    q_coef = fourier_series(qdd_raw, fs, f0, n_harmonics)
    qdd = synthesize(q_coef, f0, t, 0)
    q = synthesize(q_coef, f0, t, -2)
    reconstruction = (Psi_s @ qdd)[drive_index]
    # Galerkin reduced model (Eqs. 10-12) without the contact springs
    k0 = model.stiffness - model.params.k_t * np.outer(model.xi_vector, model.xi_vector) \
        - model.params.k_n * np.outer(model.eta_vector, model.eta_vector)
    Mr = nnm.T @ model.mass @ nnm
    Kr = nnm.T @ k0 @ nnm
    Fr = nnm.T @ model.force_vector
    G = nnm.T @ shortening_matrix(model) @ nnm
    xi_r = nnm.T @ model.xi_vector
    eta_r = nnm.T @ model.eta_vector
    f_coef = fourier_series(force, fs, f0, n_harmonics)
    f_syn = synthesize(f_coef, f0, t, 0)[0]
    lhs = np.outer(Fr, f_syn) - Mr @ qdd - Kr @ q  # (2, n_t)
    S = np.empty(t.size)
    N = np.empty(t.size)
    for k in range(t.size):
        dxi = xi_r - G @ q[:, k]
        A = np.column_stack([dxi, -eta_r])
        S[k], N[k] = np.linalg.solve(A, lhs[:, k])
    xi = xi_r @ q - 0.5 * np.einsum("it,ij,jt->t", q, G, q)
    eta = eta_r @ q
    return PaperChainResult(p_coef, nnm, spread, q, qdd, reconstruction, S - S.mean(), N - N.mean(),
                            xi - xi.mean(), eta - eta.mean(), Mr, Kr, bool(np.any(spread > phase_limit_deg)))


# ----------------------------------------------------------------------------------------------
# the working method: per-harmonic inverse identification
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class InverseResult:
    """Per-harmonic inverse identification (SI units): S, N_dyn, xi, eta, xi_dot, eta_dot (n_t,)
    mean-removed; S_coef etc. (K,) complex harmonics; residual_rms: (K,) rms misfit of the sensor
    accelerations per harmonic relative to their rms (m/s^2 per m/s^2)."""

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


def modal_damping_vector(model: FEModel, identified_zeta: np.ndarray) -> np.ndarray:
    """Damping ratio of every FE mode: the identified ratios for the structural modes they
    belong to (by order), the last identified one above, and the first below (suspension modes)."""
    modes = all_modes(model)
    zeta = np.empty(modes.frequencies_hz.size)
    structural = np.flatnonzero(modes.block_energy_fraction < 0.5)
    zeta[:] = identified_zeta[0]
    for k, idx in enumerate(structural):
        zeta[idx] = identified_zeta[min(k, len(identified_zeta) - 1)]
    return zeta


def period_coefficients(x_grid: np.ndarray, n_harmonics: int) -> np.ndarray:
    """Harmonics c_h (h = 1..K) of periodic rows sampled at M points over one period,
    x ~ mean + sum Im(c_h e^{i h w t}) (exact for M > 2K)."""
    M = x_grid.shape[-1]
    X = np.fft.fft(x_grid, axis=-1)[..., 1:n_harmonics + 1]
    return 2j * X / M


def inverse_identification(model: FEModel, zeta: np.ndarray, force: np.ndarray, acceleration: np.ndarray,
                           fs: float, f0: float, n_harmonics: int, n_iterations: int = 8) -> InverseResult:
    """Contact forces as unknown inputs, harmonic by harmonic, with the stuck linear model.

    The axial-force term of Eq. 1 (the gradient of the beam shortening in xi, G q S) mixes
    harmonics; it is moved to the known side and updated by fixed-point iteration."""
    modes = all_modes(model)
    phi = modes.shapes
    wn = 2 * np.pi * modes.frequencies_hz
    p = model.params
    w0 = 2 * np.pi * f0
    K = n_harmonics
    A_coef = fourier_series(acceleration, fs, f0, K)  # (j, K)
    F_coef = fourier_series(force, fs, f0, K)[0]  # (K,)
    b_f = phi.T @ model.force_vector
    b_xi = phi.T @ model.xi_vector
    b_eta = phi.T @ model.eta_vector
    sens = model.sensor_vectors @ phi
    G = shortening_matrix(model)
    n_dof = phi.shape[0]
    M = 8 * K  # one-period grid for the nonlinear term
    t_grid = np.arange(M) / (M * f0)
    geo_coef = np.zeros((n_dof, K), dtype=complex)  # harmonics of G q S (generalized force)
    receptance = [1.0 / (wn**2 - ((k + 1) * w0) ** 2 + 2j * zeta * wn * (k + 1) * w0) for k in range(K)]
    for it in range(max(1, n_iterations)):
        q_coef = np.zeros((n_dof, K), dtype=complex)
        r_coef = np.zeros((2, K), dtype=complex)
        residual = np.zeros(K)
        for k in range(K):
            W = (k + 1) * w0
            g = receptance[k]
            known = g * (b_f * F_coef[k] + phi.T @ geo_coef[:, k])
            H_xi = -(sens @ (g * b_xi))
            H_eta = sens @ (g * b_eta)
            disp = A_coef[:, k] / (-(W**2))  # sensor displacements
            rhs = disp - sens @ known
            Amat = np.column_stack([H_xi, H_eta])
            sol, *_ = np.linalg.lstsq(Amat, rhs, rcond=None)
            r_coef[:, k] = sol
            q_coef[:, k] = phi @ (known + g * (-b_xi * sol[0] + b_eta * sol[1]))
            residual[k] = np.linalg.norm(Amat @ sol - rhs) / max(np.linalg.norm(disp), 1e-300)
        if n_iterations <= 1:
            break
        qg = synthesize(q_coef, f0, t_grid, 0)
        S_g = synthesize(r_coef[:1], f0, t_grid, 0)[0] + p.k_t * (model.xi_vector @ qg)
        new = period_coefficients((G @ qg) * S_g, K)
        change = np.linalg.norm(new - geo_coef) / max(np.linalg.norm(new), 1e-300)
        geo_coef = new
        if change < 1e-8:
            break
    t = np.arange(acceleration.shape[1]) / fs
    q = synthesize(q_coef, f0, t, 0)  # (n_dof, n_t)
    qd = synthesize(q_coef, f0, t, 1)
    xi = model.xi_vector @ q - 0.5 * np.einsum("it,ij,jt->t", q, G, q)
    xi_lin = model.xi_vector @ q
    eta = model.eta_vector @ q
    r = synthesize(r_coef, f0, t, 0)
    S = r[0] + p.k_t * xi_lin
    N_dyn = r[1] - p.k_n * eta
    xi_dot = model.xi_vector @ qd - np.einsum("it,ij,jt->t", q, G, qd)
    eta_dot = model.eta_vector @ qd
    xi_coef = model.xi_vector @ q_coef
    eta_coef = model.eta_vector @ q_coef
    S_coef = r_coef[0] + p.k_t * xi_coef
    N_coef = r_coef[1] - p.k_n * eta_coef
    return InverseResult(S - S.mean(), N_dyn - N_dyn.mean(), xi - xi.mean(), eta - eta.mean(), xi_dot, eta_dot,
                         S_coef, N_coef, xi_coef, eta_coef, residual)
