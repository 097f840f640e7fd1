"""Periodic steady state of the reduced rig model by harmonic balance (HB) with AFT evaluation of the contact laws.

Alternating frequency/time (AFT) evaluation, as NLvib and tmdsimpy compute it.

The equations are the time integrator's (``rig.nonlinear``), in mass-normalised coordinates z:

    z'' + C z' + Omega^2 z = b f(t) + g(z, z'),
    g = -(dxi/dz) S + eta_v (N - N0) + k_t xi_v xi_lin + k_n eta_v eta

with xi = xi_v.z - z^T G z / 2 (Eq. 9 with the beam shortening), eta = eta_v.z (Eq. 8), S the
modified Valanis law (Eqs. 21-22; plus the Iwan share and the viscous term of an augmented
model) and N the normal law of ``ContactParameters``. The response is z = z_0 + sum_h
Im(Z_h e^{i h w t}), h = 1..H. Each residual evaluation synthesises z and z' on M points of one
period, runs the contact laws along that periodic path (the hysteretic friction state is
stepped around the loop, with the same step function as the integrator, until it repeats) and
projects g back onto the harmonics. Newton's method solves the residual with a Jacobian from the
laws' tangents along the path (the friction law's slope, the normal law's stiffness and
damping, the shortening's axial-force term); the tangent Jacobian is exact where the contact
sticks and close elsewhere, so Newton converges in a few steps from the linear solution or
from a neighbouring solution (``start``). The contact laws' kernels along the path are in ``rig.periodic_path``,
the solve's result and its grid's memory bound in ``rig.periodic_response``.

The time integrator stays the reference: ``tests/rig/test_harmonic_balance.py`` checks that the
harmonics agree within 0.1 % on every load case and model effect.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .nonlinear import (
    WORK_LIMIT_BYTES,
    ContactParameters,
    ReducedModel,
    friction_record,
    gib,
    stiffest_mode,
    work_limit_error,
)
from .periodic_path import friction_tangents, iwan_propagate, normal_path, periodic_friction, propagate
from .periodic_response import PeriodicResponse, grid_bytes


class HarmonicBalance:
    """HB of one reduced model and its contact laws at one excitation frequency, on the integrator's own steps.

    The integrator's dt = 2 pi / (w M). The equations are the integrator's discrete ones: velocity Verlet is the
    central difference a_n = (z_{n+1} - 2 z_n + z_{n-1}) / dt^2 with the velocity v_n = (z_{n+1} - z_{n-1}) / (2 dt) in
    the damping and the normal contact's dashpot, the half-step velocity (z_n - z_{n-1}) / dt in the explicit
    normal-force estimate and the viscous friction, and the friction law stepped once per step. On the harmonics these
    differences are exact operators (4 sin^2(h w dt / 2) / dt^2 in place of (h w)^2, sin(h w dt) / dt in place of h w),
    so the solution is the integrator's periodic orbit up to the harmonics above H, and it shares the integrator's (and
    the rig's) discretisation instead of differing from it by it.

    Parameters
    ----------
    red
        The reduced model (as for ``DualSineSimulator``).
    contact
        The contact laws (as for ``DualSineSimulator``).
    zeta
        Modal damping ratios of the reduced coordinates [-], shape (n_r,).
    w
        Excitation angular frequency [rad/s].
    H
        Number of harmonics.
    M
        Integrator steps per period (at least 4 H).

    Raises
    ------
    ValueError
        When the contact's preload drifts (not periodic: use the time integrator) or M < 4 H.
    work_limit_error
        A ``contactid.io.WorkLimitError``, made by ``rig.nonlinear.work_limit_error``, when the grid's memory
        (``grid_bytes``) passes ``rig.nonlinear.WORK_LIMIT_BYTES``; the message names the model's stiffest mode, which
        sets the step.
    """

    _last_lu: dict = {}  # the last factorised Jacobian, {(n, H, M): factor}: the next solve's chord (``forget``)

    @classmethod
    def forget(cls) -> None:
        """Drop the factorised Jacobian kept for the next solve's chord steps.

        So that what follows does not depend on what was solved before in this process (Newton's path, and so its state
        within its tolerance).
        """
        cls._last_lu = {}

    def __init__(self, red: ReducedModel, contact: ContactParameters, zeta: np.ndarray, w: float, H: int, M: int):
        if contact.preload_drift:
            raise ValueError("harmonic balance: a drifting preload is not periodic; use the time integrator")
        if M < 4 * H:
            raise ValueError(f"harmonic balance: M = {M} points cannot resolve H = {H} harmonics (M >= 4 H)")
        need = grid_bytes(M, H, red.omega.size)
        if need > WORK_LIMIT_BYTES:
            raise work_limit_error(
                f"harmonic balance: {M} points per period ({2 * np.pi / w / M:.3g} s steps) with {H} harmonics and "
                f"{red.omega.size} coordinates need {gib(need)}, above the limit of {gib(WORK_LIMIT_BYTES)} "
                "(contactid.rig.nonlinear.WORK_LIMIT_BYTES); the step follows the model's stiffest mode, at "
                f"{stiffest_mode(red)}"
            )
        self.red, self.contact, self.w, self.H, self.M = red, contact, float(w), int(H), int(M)
        self.zeta = np.asarray(zeta, dtype=float)
        self.fr = friction_record(contact)
        self.iw_w = np.asarray(contact.iwan_weights, dtype=float)
        n = red.omega.size
        dt = 2 * np.pi / (w * M)
        self.dt = dt
        h = np.arange(1, H + 1)
        ph = np.outer(np.arange(M) * dt * w, h)
        # real basis: z_j(t_k) = E[k] u_j with u_j = [mean, Re Z_1..H, Im Z_1..H]
        self.E = np.hstack([np.ones((M, 1)), np.sin(ph), np.cos(ph)])
        self.Ec = (np.roll(self.E, -1, axis=0) - np.roll(self.E, 1, axis=0)) / (2 * dt)  # v_n
        self.Eb = (self.E - np.roll(self.E, 1, axis=0)) / dt  # v_{n-1/2}
        # linear operator per mode (block of 2H + 1): Omega^2 - D2_h on Re/Im, c D1_h across
        self.D2 = (2.0 * np.sin(0.5 * h * w * dt) / dt) ** 2
        D1 = np.sin(h * w * dt) / dt
        k2 = red.omega**2
        c = 2.0 * self.zeta * red.omega
        self.L = np.zeros((n, 2 * H + 1, 2 * H + 1))
        self.L[:, 0, 0] = k2
        idx = np.arange(1, H + 1)
        self.L[:, idx, idx] = k2[:, None] - self.D2[None, :]
        self.L[:, idx + H, idx + H] = k2[:, None] - self.D2[None, :]
        self.L[:, idx, idx + H] = -c[:, None] * D1[None, :]
        self.L[:, idx + H, idx] = c[:, None] * D1[None, :]
        self.n = n
        # the Jacobian is blockdiag(L) - W B W^T with W = [xi (x) I, eta (x) I]: the contact acts through two
        # mode-space directions only (see ``factor``), so Newton solves a (2 (2H + 1))^2 system, not (n (2H + 1))^2
        # L's inverse per mode, in the same 2 x 2-per-harmonic structure: (mean, a_h, b_h) with
        # inv [[a, -b], [b, a]] = [[a, b], [-b, a]] / (a^2 + b^2)
        a, b = k2[:, None] - self.D2[None, :], c[:, None] * D1[None, :]
        den = a * a + b * b
        self.Linv = (1.0 / k2, a / den, b / den)
        xi, eta = red.xi, red.eta
        self.C = {
            key: tuple(np.tensordot(wt, part, axes=(0, 0)) for part in self.Linv)
            for key, wt in (("11", xi * xi), ("12", xi * eta), ("22", eta * eta))
        }

    # -- conversions ---------------------------------------------------------------------------
    def _block_apply(self, blk: tuple, X: np.ndarray) -> np.ndarray:
        """Apply a 2 x 2-per-harmonic operator (mean, a_h, b_h) to X.

        X (2H + 1, ...) or, with per-mode coefficients (n, ...), X (n, 2H + 1).
        """
        H = self.H
        c0, ca, cb = blk
        if np.ndim(c0) == 1:  # per mode, X (n, 2H + 1)
            re, im = X[:, 1 : H + 1], X[:, H + 1 :]
            return np.hstack([c0[:, None] * X[:, :1], ca * re + cb * im, ca * im - cb * re])
        re, im = X[1 : H + 1], X[H + 1 :]
        ca, cb = ca.reshape((-1,) + (1,) * (X.ndim - 1)), cb.reshape((-1,) + (1,) * (X.ndim - 1))
        return np.concatenate([c0 * X[:1], ca * re + cb * im, ca * im - cb * re])

    def project(self, X: np.ndarray) -> np.ndarray:
        """Return the mean, sine and cosine coefficients of the columns of X, by FFT.

        The projection onto E's basis, E.T @ X scaled by 1 / M (mean) and 2 / M (harmonics).

        Parameters
        ----------
        X
            Signals on the period's M steps, in any unit [unit of X], shape (M, ...).

        Returns
        -------
        coefficients : np.ndarray
            Mean, sine (h = 1..H) and cosine (h = 1..H) coefficients [unit of X], shape (2H + 1, ...).
        """
        F = np.fft.rfft(X, axis=0)
        H, M = self.H, self.M
        return np.concatenate([F[:1].real / M, F[1 : H + 1].imag * (-2.0 / M), F[1 : H + 1].real * (2.0 / M)])

    def synthesise(self, U: np.ndarray) -> np.ndarray:
        """Return the signals of real-basis harmonics U on the period's steps: E @ U.T by inverse FFT.

        Parameters
        ----------
        U
            Real-basis harmonics (mean, sine, cosine coefficients) of n signals, e.g. of z [kg^0.5 m],
            shape (n, 2H + 1).

        Returns
        -------
        signals : np.ndarray
            The signals on the M steps [unit of U], shape (M, n).
        """
        H, M = self.H, self.M
        F = np.zeros((M // 2 + 1, U.shape[0]), dtype=complex)
        F[0] = U[:, 0] * M
        F[1 : H + 1] = (0.5 * M) * (U[:, H + 1 :] - 1j * U[:, 1 : H + 1]).T
        return np.fft.irfft(F, n=M, axis=0)

    def to_real(self, Z: np.ndarray) -> np.ndarray:
        """Return complex harmonics in the real basis: the mean, then the real and the imaginary parts of Z_h.

        Parameters
        ----------
        Z
            Complex harmonics (column 0 the mean), e.g. of z [kg^0.5 m], shape (n, H + 1).

        Returns
        -------
        U : np.ndarray
            Real-basis harmonics [unit of Z], shape (n, 2H + 1).
        """
        return np.hstack([Z[:, :1].real, Z[:, 1:].real, Z[:, 1:].imag])

    def to_complex(self, U: np.ndarray) -> np.ndarray:
        """Return real-basis harmonics as complex ones: the mean, then Z_h from its real and imaginary parts.

        The inverse of ``to_real``.

        Parameters
        ----------
        U
            Real-basis harmonics, e.g. of z [kg^0.5 m], shape (n, 2H + 1).

        Returns
        -------
        Z : np.ndarray
            Complex harmonics (column 0 the mean) [unit of U], shape (n, H + 1).
        """
        H = self.H
        return np.hstack([U[:, :1] + 0j, U[:, 1 : H + 1] + 1j * U[:, H + 1 :]])

    def force_vector(self, force_coef: np.ndarray) -> np.ndarray:
        """Return b f(t) in the real basis from the force harmonics f = sum Im(F_h e^{ihwt}).

        Parameters
        ----------
        force_coef
            Complex force harmonics F_h, h = 1..K, of the force at d_p [N], shape (K,) (those above H are left out).

        Returns
        -------
        Fb : np.ndarray
            The modal force's real-basis harmonics [kg^0.5 m/s^2], shape (n, 2H + 1).
        """
        F = np.zeros(self.H + 1, dtype=complex)
        k = min(len(force_coef), self.H)
        F[1 : k + 1] = force_coef[:k]
        Fr = np.concatenate([[0.0], F[1:].real, F[1:].imag])
        return np.outer(self.red.force, Fr)

    def linear_start(self, force_coef: np.ndarray) -> np.ndarray:
        """Return the stuck linear system's response to the force harmonics, in the real basis.

        Parameters
        ----------
        force_coef
            Complex force harmonics F_h, h = 1..K [N], shape (K,).

        Returns
        -------
        U : np.ndarray
            Real-basis harmonics of z [kg^0.5 m], shape (n, 2H + 1).
        """
        rhs = self.force_vector(force_coef)
        return np.array([np.linalg.solve(self.L[j], rhs[j]) for j in range(self.n)])

    # -- AFT -----------------------------------------------------------------------------------
    def _normal(self, eta, deta):
        c = self.contact
        N, dN, dNd = np.empty(self.M), np.empty(self.M), np.empty(self.M)
        normal_path(
            eta,
            deta,
            c.preload,
            c.static_approach,
            c.exponent,
            c.cubic,
            c.hunt_crossley,
            bool(c.unilateral),
            N,
            dN,
            dNd,
        )
        return N, dN, dNd

    def path(self, U: np.ndarray) -> dict:
        """Return the contact laws along the periodic path of U on the steps.

        Parameters
        ----------
        U
            Real-basis harmonics of z [kg^0.5 m], shape (n, 2H + 1).

        Returns
        -------
        path : dict
            On the M steps: ``z`` [kg^0.5 m] and ``v`` (full-step velocity) [kg^0.5 m/s] (M, n); ``xi`` (with the
            shortening) and ``xi_lin`` (its linear part), ``eta`` [m]; ``dxi`` (half-step) and ``deta`` (full-step)
            [m/s]; the normal force acting ``N`` and its explicit estimate ``N_est`` [N] with their tangents
            ``dN_deta``, ``dNe_deta`` [N/m] and ``dN_ddeta``, ``dNe_ddeta`` [N s/m]; the friction force ``S`` and the
            Valanis state ``S_valanis`` [N]; the Iwan sliders' anchors ``iwan_x`` [m] and moves ``iwan_flag``
            (M, n_sliders), ``iwan_anchors`` (t = 0); ``g``, the contact forces on z [kg^0.5 m/s^2] (M, n); ``contact``,
            where the contact is closed.
        """
        r, c = self.red, self.contact
        z = self.synthesise(U)  # (M, n); the velocities are the integrator's differences (Ec, Eb)
        v = (np.roll(z, -1, axis=0) - np.roll(z, 1, axis=0)) / (2.0 * self.dt)
        vh = (z - np.roll(z, 1, axis=0)) / self.dt
        xi_lin = z @ r.xi
        Gz = z @ r.shortening
        xi = xi_lin - 0.5 * np.einsum("ti,ti->t", z, Gz)
        dxi_dq = r.xi[None, :] - Gz
        dxi = np.einsum("ti,ti->t", dxi_dq, vh)
        eta = z @ r.eta
        # the normal force acting (full-step velocity in the dashpot), and the explicit estimate the
        # friction step and the contact test use (half-step velocity)
        N, dN, dNd = self._normal(eta, v @ r.eta)
        N_est, dNe, dNed = self._normal(eta, vh @ r.eta)
        M = self.M
        S, S_val = np.zeros(M), np.empty(M)
        iw_x, iw_flag = np.zeros((M, self.iw_w.size)), np.zeros((M, self.iw_w.size), dtype=np.int8)
        periodic_friction(
            xi, np.roll(N, 1), N_est, self.fr, c.n_min, c.iwan_share, self.iw_w, 1e-12, 400, S, S_val, iw_x, iw_flag
        )
        contact = N_est > 0.0
        if c.viscous:
            S = S + c.viscous * np.where(contact, dxi, 0.0)
        g = (
            -dxi_dq * S[:, None]
            + np.outer(N - c.preload, r.eta)
            + r.k_t * np.outer(xi_lin, r.xi)
            + r.k_n * np.outer(eta, r.eta)
        )
        return {
            "z": z,
            "v": v,
            "xi": xi,
            "xi_lin": xi_lin,
            "dxi": dxi,
            "eta": eta,
            "deta": v @ r.eta,
            "N": N,
            "dN_deta": dN,
            "dN_ddeta": dNd,
            "N_est": N_est,
            "dNe_deta": dNe,
            "dNe_ddeta": dNed,
            "S": S,
            "S_valanis": S_val,
            "iwan_x": iw_x,
            "iwan_flag": iw_flag,
            "g": g,
            "contact": contact,
            "iwan_anchors": iw_x[0].copy(),
        }

    def residual(self, U: np.ndarray, Fb: np.ndarray, p: dict | None = None) -> tuple[np.ndarray, dict]:
        """Return the HB residual R = L U - Fb - project(g) of the harmonics U against the force Fb.

        With the contact path it used (``path``, or ``p`` where given).

        Parameters
        ----------
        U
            Real-basis harmonics of z [kg^0.5 m], shape (n, 2H + 1).
        Fb
            The force's real-basis harmonics (``force_vector``) [kg^0.5 m/s^2], shape (n, 2H + 1).
        p
            The contact path of U (``path``), or None to compute it.

        Returns
        -------
        R : np.ndarray
            The residual, real basis [kg^0.5 m/s^2], shape (n, 2H + 1).
        path : dict
            The contact path (``path``).
        """
        p = self.path(U) if p is None else p
        R = np.einsum("jab,jb->ja", self.L, U) - Fb - self.project(p["g"]).T
        return R, p

    def jacobian(self, p: dict) -> np.ndarray:
        """Return the dense Jacobian dR/dU that ``factor`` inverts (Newton uses that).

        blockdiag(L) - W B W^T with ``contact_blocks``' B, assembled term by term, and the beam shortening's axial-force
        term (G S) that the factor leaves out; the shortening's share of the friction direction (dxi/dz = xi_v - G z) is
        left out of both.

        Parameters
        ----------
        p
            The contact path (``path``).

        Returns
        -------
        J : np.ndarray
            The Jacobian, mode-major ordering [1/s^2], shape (n (2H + 1), n (2H + 1)).
        """
        r = self.red
        B = self.contact_blocks(p)
        nb = B.shape[0] // 2
        Jnl = (
            np.kron(np.outer(r.xi, r.xi), B[:nb, :nb])
            + np.kron(np.outer(r.xi, r.eta), B[:nb, nb:])
            + np.kron(np.outer(r.eta, r.eta), B[nb:, nb:])
        )
        Jnl += np.kron(r.shortening, self.project(p["S"][:, None] * self.E))
        return scipy.linalg.block_diag(*self.L) - Jnl

    def contact_blocks(self, p: dict) -> np.ndarray:
        """Return B of the Jacobian's contact part W B W^T, W = [xi (x) I, eta (x) I].

        The friction law's linearised step recurrence around the path (its memory and its dependence on N exact, the
        Iwan sliders' with their anchors' memory), the normal law's tangents, the viscous term. Left out: the beam
        shortening's share (dxi/dz = xi_v - G z and the axial-force term G S), second order in z, which costs Newton a
        step, not its convergence.

        Parameters
        ----------
        p
            The contact path (``path``).

        Returns
        -------
        B : np.ndarray
            The contact's blocks (xi-xi, xi-eta, eta-eta) [N/m], shape (2 (2H + 1), 2 (2H + 1)).
        """
        c = self.contact
        E = self.E
        M = self.M
        nb = E.shape[1]
        coef = np.empty((M, 5))
        friction_tangents(p["xi"], np.roll(p["N"], 1), p["N_est"], p["S_valanis"], self.fr, c.n_min, coef)
        dN_full = p["dN_deta"][:, None] * E + p["dN_ddeta"][:, None] * self.Ec
        dN_est = p["dNe_deta"][:, None] * E + p["dNe_ddeta"][:, None] * self.Eb
        zero = np.zeros((M, nb))
        dS = np.empty((M, 2 * nb))
        dxi_cols, dN_est_cols = np.hstack([E, zero]), np.hstack([zero, dN_est])  # columns: U's xi part, then its N part
        propagate(coef, dxi_cols, np.hstack([zero, np.roll(dN_full, 1, axis=0)]), dN_est_cols, dS)
        dS *= (1.0 - c.iwan_share) * p["contact"][:, None]
        if c.iwan_share:  # the Iwan element's share, linearised with its sliders' memory
            dS_iw = np.empty_like(dS)
            iwan_propagate(
                p["xi"],
                p["N_est"],
                p["iwan_x"],
                p["iwan_flag"],
                self.iw_w,
                self.fr[0],
                self.fr[1],
                self.fr[4],
                dxi_cols,
                dN_est_cols,
                dS_iw,
            )
            dS += c.iwan_share * dS_iw
        if c.viscous:
            dS[:, :nb] += c.viscous * p["contact"][:, None] * self.Eb
        P = self.project(dS)
        B = np.zeros((2 * nb, 2 * nb))
        B[:nb, :nb] = self.red.k_t * np.eye(nb) - P[:, :nb]
        B[:nb, nb:] = -P[:, nb:]
        B[nb:, nb:] = self.project((p["dN_deta"] + self.red.k_n)[:, None] * E + p["dN_ddeta"][:, None] * self.Ec)
        return B

    def factor(self, p: dict) -> tuple:
        """Return the Newton matrix along path ``p``, factorised by the Woodbury identity.

        J = D - W B W^T with D = blockdiag(L) (the linear modes, fixed) and the contact's B; J^-1 r = D^-1 (r + W B y)
        where (I - C B) y = W^T D^-1 r and C = W^T D^-1 W. One (2 (2H + 1))^2 LU per Jacobian.

        Parameters
        ----------
        p
            The contact path (``path``).

        Returns
        -------
        factor : tuple
            (this HarmonicBalance, B, the LU factor of I - C B), for ``apply_inverse``.
        """
        B = self.contact_blocks(p)
        nb = B.shape[0] // 2
        C, ap = self.C, self._block_apply
        CB = np.vstack([ap(C["11"], B[:nb]) + ap(C["12"], B[nb:]), ap(C["12"], B[:nb]) + ap(C["22"], B[nb:])])
        lu = scipy.linalg.lu_factor(np.eye(2 * nb) - CB, check_finite=False)
        return (self, B, lu)

    @staticmethod
    def apply_inverse(f: tuple, R: np.ndarray) -> np.ndarray:
        """Return J^-1 R for a factor ``f`` of ``factor``.

        The factor may be a neighbouring model's (a chord step): it carries its own linear part.

        Parameters
        ----------
        f
            A factor made by ``factor``.
        R
            A residual, real basis, mode-major [kg^0.5 m/s^2], shape (n, 2H + 1).

        Returns
        -------
        step : np.ndarray
            J^-1 R, real-basis harmonics of z [kg^0.5 m], shape (n, 2H + 1).
        """
        hb, B, lu = f
        xi, eta = hb.red.xi, hb.red.eta
        DR = hb._block_apply(hb.Linv, R)
        s = np.concatenate([xi @ DR, eta @ DR])
        By = B @ scipy.linalg.lu_solve(lu, s, check_finite=False)
        nb = R.shape[1]
        return hb._block_apply(hb.Linv, R + np.outer(xi, By[:nb]) + np.outer(eta, By[nb:]))

    # -- Newton --------------------------------------------------------------------------------
    def solve(
        self, force_coef: np.ndarray, start: np.ndarray | None = None, tol: float = 1e-8, max_iter: int = 40
    ) -> PeriodicResponse:
        """Find the periodic steady state by Newton's method from ``start`` or the linear solution.

        Converged when the residual is below ``tol`` of the force's norm (both in the real basis). Steps are backtracked
        on the residual norm; the last factorised Jacobian of this size (a neighbouring solve's) is reused as a chord
        until it stops cutting the residual threefold.

        Parameters
        ----------
        force_coef
            Complex force harmonics F_h, h = 1..K, of the force at d_p [N], shape (K,).
        start
            Complex harmonics Z of z to start from [kg^0.5 m], shape (n, H' + 1) for any H'; None: the linear solution.
        tol
            Relative residual at which Newton stops [-].
        max_iter
            The most Newton iterations.

        Returns
        -------
        response : PeriodicResponse
            The steady state, with whether Newton converged.
        """
        Fb = self.force_vector(force_coef)
        scale = max(np.linalg.norm(Fb), 1e-300)
        if start is None:
            U = self.linear_start(force_coef)
        else:
            Z0 = np.zeros((self.n, self.H + 1), dtype=complex)
            k = min(start.shape[1], self.H + 1)
            Z0[:, :k] = start[:, :k]
            U = self.to_real(Z0)
        R, p = self.residual(U, Fb)
        err = np.linalg.norm(R) / scale
        converged = err < tol
        it = 0
        # start from the last factorised Jacobian of this size (a neighbouring solve's): a chord that is
        # refreshed as soon as it stops cutting the residual threefold
        lu, fresh = HarmonicBalance._last_lu.get((self.n, self.H, self.M)), False
        while not converged and it < max_iter:
            it += 1
            if lu is None:
                lu, fresh = self.factor(p), True
                HarmonicBalance._last_lu = {(self.n, self.H, self.M): lu}
            step = self.apply_inverse(lu, -R)
            lam, better = 1.0, False
            for _ in range(8):  # backtracking on the residual norm
                U_try = U + lam * step
                R_try, p_try = self.residual(U_try, Fb)
                err_try = np.linalg.norm(R_try) / scale
                if np.isfinite(err_try) and err_try < err:
                    better = True
                    break
                lam *= 0.5
            if not better:
                if fresh:
                    break  # even the current tangent gives no descent: stop (not converged)
                lu = None  # a stale Jacobian: refresh it and try again
                continue
            # keep the factorised Jacobian while it still cuts the residual threefold (chord steps)
            if lam < 1.0 or err_try > 0.3 * err:
                lu = None
            fresh = False
            U, R, p, err = U_try, R_try, p_try, err_try
            converged = err < tol
        return self._response(U, p, converged, it, err)

    def _response(self, U, p, converged, it, err) -> PeriodicResponse:
        Z = self.to_complex(U)
        A = -np.concatenate([[0.0], self.D2]) * Z  # the integrator's acceleration: the second difference
        grid = {k: p[k] for k in ("z", "v", "xi", "eta", "dxi", "deta", "N", "S", "S_valanis")}
        grid["a"] = self.E @ self.to_real(A).T
        grid["t"] = np.arange(self.M) * self.dt
        return PeriodicResponse(Z, A, self.w, grid, bool(converged), int(it), float(err), p["iwan_anchors"])
