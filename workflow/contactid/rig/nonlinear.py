"""Virtual rig, nonlinear part: response-controlled dual-sine tests (Section 3).

Model: the structure of the linear chain reduced to the lowest ``n_modes`` modes
of the stuck structure plus the static responses to a unit tangential and a
unit normal contact force (residual flexibility), re-orthogonalised, so the
basis holds the contact's u and eta when it slips or bounces. The linear
contact springs are removed again on the right-hand side and replaced by the
contact laws:

    M q'' + C q' + K_0 q = F f(t) - dxi/dq S + deta/dq (N - P(t))

with xi = xi_lin(q) - q^T G q / 2 (Eq. 9 with the beam shortening, whose
gradient carries the axial-force term of Eq. 1), eta = eta_lin(q) (Eq. 8),
S from the modified Valanis law (Eqs. 21-22) with N the total normal force,
N = N0 ((delta0 - eta) / delta0)^p while in contact (zero when it opens), and
P(t) the static preload (N0 unless it drifts). The block's dynamics (Eqs. 2-4)
are in M and K_0.

Time stepping: explicit central differences (velocity Verlet) with the
diagonal modal damping taken implicitly, at ``oversampling`` times the output
rate; the friction state is advanced with Heun's method in xi per step.

The kernels of the time step (the contact laws and ``integrate``) are in ``rig.integrator``, the response
control (``control_response``) in ``rig.control``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from ..beam_model import FEModel, all_modes, fix_signs, shortening_matrix
from ..friction import slip_limit_flag
from ..harmonics import harmonic_amplitudes, periodic_harmonics
from .integrator import KernelContact, KernelDrive, KernelModel, KernelRecord, integrate

progress = logging.getLogger(__name__)  # the response control's iterations (rig.control logs with it)


@dataclass(frozen=True)
class ReducedModel:
    """Reduced model in mass-normalised coordinates z (q = basis @ z).

    omega: (n_r,) rad/s of the reduced stuck system; basis: (n_dof, n_r);
    xi, eta: (n_r,) linear contact coordinates; shortening: (n_r, n_r) G;
    force: (n_r,) generalized force of a unit force at d_p; drive: (n_r,) w at d_p;
    sensors: (n_sensors, n_r) w at the sensors; beam_mode: (n_r,) True where
    the block carries less than half of the kinetic energy; k_t, k_n: the
    linear springs built into omega (N/m).
    """

    omega: np.ndarray
    basis: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    shortening: np.ndarray
    force: np.ndarray
    drive: np.ndarray
    sensors: np.ndarray
    beam_mode: np.ndarray
    k_t: float
    k_n: float


# Bounded work. The integrator's step follows the model's stiffest mode (``stable_oversampling``), and a model
# identified from a record read in the wrong units can have one at GHz: the gap diagnosis of a random test whose
# accelerations were in g read as m/s^2 had a normal-contact mode at 3.1 GHz and asked for 2.3 million steps per
# sample, a 30.6 GiB harmonic-balance grid for one period. These limits turn that into an error that names the
# quantity, the limit and the likely cause, before anything is allocated.
MAX_STEPS_PER_SAMPLE = 1024
"""The most integration steps per record sample ``stable_oversampling`` gives (the model's stiffest mode up to
1024 x 1.6 / (2 pi) = 261 times the sampling rate). Legitimate models need 8 (the default oversampling; 9 after the
gap diagnosis' mass refits, ``gap.model.KN_REFIT_ABOVE``), 79 (the viscous-friction candidate at the end of its
domain, 1e5 N s/m, at 5120 Hz) and 169 (the project's structure with k_n at the stiffness fit's upper search bound,
1e11 N/m, at 5120 Hz: a 219 kHz mode): the limit leaves six times the largest. Past it a ``WorkLimitError`` names
the mode, the contact spring that makes it and the likely cause (a contact stiffness no pin can have, identified from
a record read in the wrong units)."""

WORK_LIMIT_BYTES = 1 << 30
"""The most memory (bytes, 1 GiB) one simulation's stored signals (``DualSineSimulator.run``, ``record_bytes``) or
one harmonic-balance grid (``rig.harmonic_balance.grid_bytes``) may take. With the job's own memory (the largest job
of a run on the foreign records peaked at 0.75 GiB) and the copies the callers make of a stored record (a sixth of
it), no job passes about 2.5 GiB, below the 4 GiB a job may use. Legitimate work stays far below it (estimates by
those two functions): the rig's dual-sine record (16384 samples, eight steps each, with its margins) 89 MB; the gap
diagnosis' harmonic balance of a 54 Hz record at 5400 Hz (800 points, 18 harmonics) 4.6 MB, and the longest record
it integrates on the project's rig (174 periods of 754 steps) 44 MB; a record at 51.2 kHz driven at 10 Hz (41000
steps per period) 0.2-0.3 GiB. Past it a ``WorkLimitError``."""


def work_limit_error(message: str):
    """A WorkLimitError with ``message`` (imported when raised)."""
    from ..io import WorkLimitError  # here: this module is imported where xarray is not needed

    return WorkLimitError(message)


def gib(n_bytes: float) -> str:
    """A memory size for a message ("30.6 GiB", "12 MiB")."""
    return f"{n_bytes / 2**30:.3g} GiB" if n_bytes >= 2**30 else f"{n_bytes / 2**20:.3g} MiB"


def frequency_text(f_hz: float) -> str:
    """A frequency for a message, in Hz, kHz, MHz or GHz."""
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if abs(f_hz) >= scale:
            return f"{f_hz / scale:.3g} {unit}"
    return f"{f_hz:.4g} Hz"


def record_bytes(n_steps: int, n_r: int, state: bool = True) -> int:
    """Memory (bytes) of ``DualSineSimulator.run``'s stored signals over ``n_steps`` steps of a reduced model of
    ``n_r`` coordinates, with the coordinates and velocities (``state``) or without: measured 313 (336 with them)
    bytes per step at n_r = 11, 16 (10 + n_r (1 + 2 state)) bytes bound it (the stored arrays and the temporaries)."""
    return int(n_steps) * 16 * (10 + int(n_r) * (3 if state else 1))


def stiffest_mode(red: ReducedModel) -> str:
    """The reduced model's stiffest mode in words: its frequency and, where a contact spring carries most of its
    strain energy (k eta_i^2 / omega_i^2 of the mass-normalised mode), which spring and its stiffness."""
    i = int(np.argmax(red.omega))
    w2 = max(float(red.omega[i]) ** 2, 1e-300)
    shares = {
        "normal": float(red.k_n) * float(red.eta[i]) ** 2 / w2,
        "tangential": float(red.k_t) * float(red.xi[i]) ** 2 / w2,
    }
    name = max(shares, key=shares.get)
    text = f"{frequency_text(red.omega[i] / (2 * np.pi))}"
    if shares[name] > 0.5:
        k = red.k_n if name == "normal" else red.k_t
        other = ("k_t", red.k_t) if name == "normal" else ("k_n", red.k_n)
        sym = "k_n" if name == "normal" else "k_t"
        text += (
            f", the {name} contact's mode (its spring {sym} = {k:.3g} N/m carries {100 * min(shares[name], 1.0):.0f} % "
            f"of the mode's strain energy; {other[0]} = {other[1]:.3g} N/m)"
        )
    else:
        text += f" (k_t = {red.k_t:.3g} N/m, k_n = {red.k_n:.3g} N/m)"
    return text


def stable_oversampling(red: ReducedModel, fs: float, q_min: int, stiffening: float = 1.0, viscous: float = 0.0) -> int:
    """Integration steps per sample at ``fs`` (Hz), at least ``q_min``, at which the explicit central differences keep
    a margin: omega_max dt <= 1.6 (omega_max (rad/s) times ``stiffening``, a hardening normal law's tangent ratio;
    2 is the edge) and the viscous friction's rate sigma_2 |dxi/dq|^2 (1/s; ``viscous`` sigma_2 in N s/m), which a step
    takes explicitly, times dt at most 1 (2 is the edge: the rig's records blew up at sigma_2 = 2e4 N s/m, rate x dt
    1.96, with the default eight steps per sample).

    Raises ``io.WorkLimitError`` past ``MAX_STEPS_PER_SAMPLE``, naming the stiffest mode (and the contact spring
    that makes it) or the viscous rate."""
    q_mode = int(np.ceil(stiffening * red.omega.max() / (1.6 * fs)))
    rate = float(viscous) * float(red.xi @ red.xi)
    q_rate = int(np.ceil(rate / fs))
    q = max(int(q_min), q_mode, q_rate)
    if q > MAX_STEPS_PER_SAMPLE:
        if q_mode >= q_rate:
            f_max = float(red.omega.max()) / (2 * np.pi)
            what = (
                f"the model's stiffest mode is at {stiffest_mode(red)}, {f_max / fs:.3g} x the sampling rate {fs:g} Hz"
                + (f" (x {stiffening:.3g}, the normal law's hardening)" if stiffening != 1.0 else "")
            )
        else:
            what = (
                f"the viscous friction's rate sigma_2 |dxi/dq|^2 = {rate:.3g} 1/s (sigma_2 = {viscous:.3g} N s/m) is "
                f"{rate / fs:.3g} x the sampling rate {fs:g} Hz"
            )
        raise work_limit_error(
            f"{what}: the explicit integration would need {q} steps per sample, above the limit of "
            f"{MAX_STEPS_PER_SAMPLE} (contactid.rig.nonlinear.MAX_STEPS_PER_SAMPLE; a legitimate model needs 8 to "
            "about 170)"
        )
    return q


def reduced_model(model: FEModel, n_modes: int, static_correction: bool = True) -> ReducedModel:
    """Basis of the lowest ``n_modes`` stuck modes plus the static responses to a unit tangential
    and a unit normal contact force and to the excitation (residual flexibility of the truncated
    modes for every load the model carries)."""
    modes = all_modes(model)
    phi = modes.shapes[:, :n_modes]
    if static_correction:
        K = model.stiffness
        psi = np.linalg.solve(K, np.column_stack([model.xi_vector, model.eta_vector, model.force_vector]))
        phi = np.column_stack([phi, psi])
    Kr = phi.T @ model.stiffness @ phi
    Mr = phi.T @ model.mass @ phi
    lam, vec = scipy.linalg.eigh(Kr, Mr)
    basis = fix_signs(phi @ vec)
    p = model.params
    frac = (
        p.block_mass * ((model.block_lateral_vector @ basis) ** 2 + (model.block_axial_vector @ basis) ** 2)
        + p.block_inertia * basis[model.thetas_dof] ** 2
    )
    G = shortening_matrix(model)
    return ReducedModel(
        omega=np.sqrt(np.clip(lam, 0, None)),
        basis=basis,
        xi=model.xi_vector @ basis,
        eta=model.eta_vector @ basis,
        shortening=basis.T @ G @ basis,
        force=basis.T @ model.force_vector,
        drive=model.force_vector @ basis,
        sensors=model.sensor_vectors @ basis,
        beam_mode=frac < 0.5,
        k_t=p.k_t,
        k_n=p.k_n,
    )


@dataclass(frozen=True)
class ContactParameters:
    """Contact laws of the rig (SI units).

    friction: (e_f, k_c, e_t, kappa, mu) of Eqs. 21-22; regularization: how the law is read
    (``none``: as printed, ``slip_limit``; see ``contactid.friction``); preload N0 (N);
    static_approach delta0 (m), exponent p and cubic hardening k_3 (N/m^3) of the normal law; hunt_crossley
    alpha (s/m); viscous sigma_2 (N s/m); iwan_share (0..1) and the Iwan
    sliders' slip-limit weights (sum 1); preload_drift (relative, over the record).
    """

    friction: tuple
    preload: float
    static_approach: float
    exponent: float
    hunt_crossley: float = 0.0
    viscous: float = 0.0
    iwan_share: float = 0.0
    iwan_weights: np.ndarray = field(default_factory=lambda: iwan_slip_weights(16))
    preload_drift: float = 0.0
    n_min: float = 1e-6
    unilateral: bool = True
    regularization: str = "none"
    cubic: float = 0.0


def friction_record(contact: ContactParameters) -> np.ndarray:
    """The kernels' friction record: (e_f, k_c, e_t, kappa, mu, slip_limit) with slip_limit 1.0 for the
    ``slip_limit`` reading of Eq. 21 and 0.0 for the law as printed."""
    return np.array([*(float(x) for x in contact.friction), float(slip_limit_flag(contact.regularization))])


def iwan_slip_weights(n: int, spread: float = 0.8) -> np.ndarray:
    """Slip limits of n Maxwell-slip sliders as fractions of mu N: thresholds spread
    uniformly over [1 - spread, 1 + spread] (relative), each slider with stiffness
    e_0 / n, normalised so that they sum to 1."""
    w = np.linspace(1 - spread, 1 + spread, n)
    return w / w.sum()


@dataclass
class SteadyStateLog:
    """How steady state was reached: the driving-point harmonic amplitudes
    A1 (at w) and A3 (at 3w) of each chunk, and the relative change between chunks."""

    a1: list = field(default_factory=list)
    a3: list = field(default_factory=list)
    change: list = field(default_factory=list)


def force_coefficients(F1, F3) -> np.ndarray:
    """Complex harmonics c_h (h = 1..H) of the excitation, f = sum_h Im(c_h e^{i h w t}) (N):
    [F1, 0, F3] for two amplitudes, or F1 itself (an array) when F3 is None."""
    if F3 is None:
        return np.atleast_1d(np.asarray(F1, dtype=complex))
    return np.array([F1, 0.0, F3], dtype=complex)


class DualSineSimulator:
    """Time integration of the reduced rig model under f = F1 sin(wt) + F3 sin(3wt)
    (or any periodic force given by its harmonics)."""

    def __init__(self, red: ReducedModel, contact: ContactParameters, zeta: np.ndarray, dt: float):
        self.red = red
        self.contact = contact
        self.zeta = np.asarray(zeta, dtype=float)
        self.dt = float(dt)
        self.fr = friction_record(contact)
        self.iw_w = np.asarray(contact.iwan_weights, dtype=float)
        self.reset()

    def reset(self):
        """Return to rest: zero coordinates, velocities, friction state and Iwan sliders at t = 0, no preload drift and
        no last chunk."""
        n = self.red.omega.size
        self.z = np.zeros(n)
        self.v = np.zeros(n)
        self.state = np.zeros(3)
        self.x_sl = np.zeros(self.iw_w.size)
        self.t = 0.0
        self.last_chunk = None
        self.drift_rate = 0.0
        self.drift_t0 = 0.0

    def linear_frf(self, w: float) -> complex:
        """Driving-point accelerance of the stuck linear reduced system at w (m/s^2/N)."""
        r = self.red
        x = r.force / (r.omega**2 - w**2 + 2j * self.zeta * r.omega * w)
        return complex(-(w**2) * (r.drive @ x))

    def start_from_linear(self, F1, F3, w: float):
        """Initial state: the stuck linear system's steady state at t = 0 (force as in ``run``)."""
        r = self.red
        self.reset()
        for k, F in enumerate(force_coefficients(F1, F3)):
            if F == 0:
                continue
            h = k + 1
            X = F * r.force / (r.omega**2 - (h * w) ** 2 + 2j * self.zeta * r.omega * h * w)
            self.z += X.imag
            self.v += h * w * X.real
        self.state[1] = r.xi @ self.z
        # the friction state starts at the stuck spring force
        self.state[0] = r.k_t * (r.xi @ self.z)

    def run(self, F1, F3, w: float, n_steps: int, store_from: int | None = None, state: bool = True) -> dict:
        """Advance n_steps under f = F1 sin(wt) + F3 sin(3wt) (N), or, with F3 None, under
        f = sum_h Im(F1[h-1] e^{i h w t}) for a complex coefficient array F1; returns the stored
        signals (from ``store_from``) at the step rate, the coordinates "z" and velocities "v" only with ``state``
        (a third of the stored numbers: the gap's simulations of a whole record do not read them)."""
        coef = force_coefficients(F1, F3)
        n_store = 0 if store_from is None else n_steps - store_from
        n_r = self.red.omega.size
        need = record_bytes(n_store, n_r, state)
        if need > WORK_LIMIT_BYTES:
            per_period = 2 * np.pi / (float(w) * self.dt) if w else float("nan")
            raise work_limit_error(
                f"time integration: storing {n_store} steps ({n_store / per_period:.4g} periods of "
                f"{per_period:.6g} steps, dt = {self.dt:.3g} s, {getattr(self, 'oversampling', '?')} steps per sample) "
                f"of a {n_r}-coordinate model needs {gib(need)}, above the limit of {gib(WORK_LIMIT_BYTES)} "
                "(contactid.rig.nonlinear.WORK_LIMIT_BYTES): a record this long, or a model this stiff "
                f"(its stiffest mode at {stiffest_mode(self.red)}), is beyond what one job simulates"
            )
        out = {k: np.empty(n_store) for k in ("S", "N", "xi", "eta", "f", "dxi", "deta")}
        out_a = np.empty((n_store, n_r))
        out_z = np.empty((n_store if state else 0, n_r))
        out_v = np.empty((n_store if state else 0, n_r))
        c = self.contact
        r = self.red
        t_start = self.t
        self.t = integrate(
            self.z,
            self.v,
            self.state,
            self.x_sl,
            self.t,
            n_steps,
            self.dt,
            KernelModel(r.omega, self.zeta, r.xi, r.eta, r.shortening, r.force, float(r.k_t), float(r.k_n)),
            KernelContact(
                self.fr,
                float(c.preload),
                float(c.static_approach),
                float(c.exponent),
                float(c.cubic),
                float(c.hunt_crossley),
                bool(c.unilateral),
                float(c.viscous),
                float(c.iwan_share),
                self.iw_w,
            ),
            KernelDrive(
                np.ascontiguousarray(coef.real),
                np.ascontiguousarray(coef.imag),
                float(w),
                float(self.drift_rate),
                float(self.drift_t0),
            ),
            n_steps if store_from is None else store_from,
            KernelRecord(
                out_a, out_z, out_v, out["S"], out["N"], out["xi"], out["eta"], out["f"], out["dxi"], out["deta"]
            ),
        )
        first = 1 + (n_steps if store_from is None else store_from)
        out["t"] = t_start + self.dt * np.arange(first, first + n_store)
        out["a"] = out_a
        if state:
            out["z"] = out_z
            out["v"] = out_v
        return out

    def snapshot(self) -> tuple:
        """The integrator's state (to return to with ``restore``)."""
        return (
            self.z.copy(),
            self.v.copy(),
            self.state.copy(),
            self.x_sl.copy(),
            self.t,
            self.drift_rate,
            self.drift_t0,
        )

    def restore(self, snap: tuple) -> None:
        """Return the integrator to a state ``snapshot`` took."""
        z, v, state, x_sl, t, rate, t0 = snap
        self.z[:], self.v[:], self.state[:], self.x_sl[:] = z, v, state, x_sl
        self.t, self.drift_rate, self.drift_t0 = t, rate, t0

    def settle(
        self, F1, F3, w: float, chunk_periods: int = 8, tol: float = 1e-4, min_chunks: int = 3, max_chunks: int = 200
    ) -> tuple[np.ndarray, SteadyStateLog, bool]:
        """Run chunks of ``chunk_periods`` periods until the driving-point harmonics
        at w and 3w change by less than ``tol`` (relative) from one chunk to the next.
        Returns ([A1, A3] complex of the last chunk, log, converged); the last chunk's signals (``run``'s dict)
        stay in ``last_chunk`` (without the coordinates and velocities), so that a settled response can be recorded
        from them."""
        n = int(round(chunk_periods * 2 * np.pi / w / self.dt))
        # whole steps per period (the gap's model; the rig's step does not divide the period): the harmonics of
        # whole periods by FFT, equal to the least squares to rounding at a fifth of its cost
        n_per = 2 * np.pi / w / self.dt
        whole = abs(n_per - round(n_per)) < 1e-9 * n_per and n % round(n_per) == 0
        log = SteadyStateLog()
        prev = None
        for k in range(max_chunks):
            out = self.run(F1, F3, w, n, store_from=0, state=False)
            self.last_chunk = out
            acc = out["a"] @ self.red.drive
            if whole:
                c = periodic_harmonics(acc, out["t"][0], w, round(n_per), 3)[0, [0, 2]]
            else:
                c = harmonic_amplitudes(acc, out["t"], w, (1, 3))
            log.a1.append(abs(c[0]))
            log.a3.append(abs(c[1]))
            if prev is not None:
                ch = float(np.max(np.abs(c - prev) / np.abs(c)))
                log.change.append(ch)
                if k + 1 >= min_chunks and ch < tol:
                    return c, log, True
            prev = c
        return prev, log, False
