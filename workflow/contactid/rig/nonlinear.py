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

    The coordinates z are mass-normalised (basis^T M basis = I): z is in kg^0.5 m, and a row vector that maps z to a
    displacement (xi, eta, the drive point's and the sensors' w) is in kg^-0.5. n_r is the number of reduced coordinates
    (the modes kept plus the static responses), n_dof the FE model's degrees of freedom.

    Attributes
    ----------
    omega
        Natural angular frequencies of the reduced stuck system [rad/s], shape (n_r,).
    basis
        The basis, q = basis @ z (mass-normalised) [kg^-0.5] on the translations ([rad/(kg^0.5 m)] on the
        rotations), shape (n_dof, n_r).
    xi
        The linear tangential contact coordinate, xi_lin = xi @ z [kg^-0.5], shape (n_r,).
    eta
        The linear normal contact coordinate, eta = eta @ z [kg^-0.5], shape (n_r,).
    shortening
        G, the beam shortening's matrix on z (xi = xi_lin - z^T G z / 2) [kg^-1 m^-1], shape (n_r, n_r).
    force
        The generalized force of a unit force at d_p [kg^-0.5] (per N of the force), shape (n_r,).
    drive
        w at d_p, the drive point's displacement w = drive @ z [kg^-0.5], shape (n_r,).
    sensors
        w at the sensors, each sensor's displacement = sensors @ z [kg^-0.5], shape (n_sensors, n_r).
    beam_mode
        True where the block carries less than half of the coordinate's kinetic energy [-] (boolean), shape (n_r,).
    k_t
        The linear tangential contact spring built into omega [N/m].
    k_n
        The linear normal contact spring built into omega [N/m].
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


def work_limit_error(message: str) -> Exception:
    """Return a WorkLimitError with ``message`` (imported when raised).

    Parameters
    ----------
    message
        The error's message.

    Returns
    -------
    error : Exception
        The ``io.WorkLimitError``, for the caller to raise.
    """
    from ..io import WorkLimitError  # here: this module is imported where xarray is not needed

    return WorkLimitError(message)


def gib(n_bytes: float) -> str:
    """Return a memory size written for a message ("30.6 GiB", "12 MiB").

    Parameters
    ----------
    n_bytes
        The memory size, a count of bytes [-].

    Returns
    -------
    text : str
        The size in GiB from 1 GiB up, else in MiB.
    """
    return f"{n_bytes / 2**30:.3g} GiB" if n_bytes >= 2**30 else f"{n_bytes / 2**20:.3g} MiB"


def frequency_text(f_hz: float) -> str:
    """Return a frequency written for a message, in Hz, kHz, MHz or GHz.

    Parameters
    ----------
    f_hz
        The frequency [Hz].

    Returns
    -------
    text : str
        The frequency to three or four significant digits with its unit.
    """
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if abs(f_hz) >= scale:
            return f"{f_hz / scale:.3g} {unit}"
    return f"{f_hz:.4g} Hz"


def record_bytes(n_steps: int, n_r: int, state: bool = True) -> int:
    """Return the memory (bytes) of ``DualSineSimulator.run``'s stored signals.

    Over ``n_steps`` steps of a reduced model of ``n_r`` coordinates, with the coordinates and velocities (``state``) or
    without: measured 313 (336 with them) bytes per step at n_r = 11, 16 (10 + n_r (1 + 2 state)) bytes bound it (the
    stored arrays and the temporaries).

    Parameters
    ----------
    n_steps
        The steps stored.
    n_r
        The reduced model's number of coordinates.
    state
        Whether the coordinates and velocities are stored too.

    Returns
    -------
    n_bytes : int
        The bound on the memory, in bytes.
    """
    return int(n_steps) * 16 * (10 + int(n_r) * (3 if state else 1))


def stiffest_mode(red: ReducedModel) -> str:
    """Return the reduced model's stiffest mode in words.

    Its frequency and, where a contact spring carries most of its strain energy (k eta_i^2 / omega_i^2 of the
    mass-normalised mode), which spring and its stiffness.

    Parameters
    ----------
    red
        The reduced model.

    Returns
    -------
    text : str
        The mode's frequency (in Hz, kHz, MHz or GHz) and the contact springs' stiffnesses (N/m), for a message.
    """
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
    """Return the integration steps per sample at which the explicit central differences keep a margin.

    The steps per sample at ``fs``, at least ``q_min``, keep omega_max dt <= 1.6 (omega_max (rad/s) times
    ``stiffening``, a hardening normal law's tangent ratio; 2 is the edge) and the viscous friction's rate sigma_2
    |dxi/dq|^2 (1/s), which a step takes explicitly, times dt at most 1 (2 is the edge: the rig's records blew up at
    sigma_2 = 2e4 N s/m, rate x dt 1.96, with the default eight steps per sample).

    Parameters
    ----------
    red
        The reduced model (its stiffest mode, omega_max = max ``red.omega``, and ``red.xi``).
    fs
        The record's sampling rate [Hz].
    q_min
        The fewest steps per sample.
    stiffening
        The factor on the stiffest mode's angular frequency, a hardening normal law's tangent ratio [-].
    viscous
        The viscous friction's sigma_2 [N s/m].

    Returns
    -------
    q : int
        The integration steps per sample.

    Raises
    ------
    WorkLimitError
        Past ``MAX_STEPS_PER_SAMPLE`` (raised through ``work_limit_error``), naming the stiffest mode (and the
        contact spring that makes it) or the viscous rate.
    """  # noqa: DOC503
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
    """Return the reduced model on a basis of the lowest stuck modes plus static responses.

    The basis holds the lowest ``n_modes`` stuck modes plus the static responses to a unit tangential and a unit normal
    contact force and to the excitation (residual flexibility of the truncated modes for every load the model carries),
    re-orthogonalised.

    Parameters
    ----------
    model
        The assembled FE model of the structure, the contact springs included.
    n_modes
        The number of stuck modes kept.
    static_correction
        Whether the static responses are added to the basis.

    Returns
    -------
    red : ReducedModel
        The reduced model (n_r = n_modes + 3 coordinates with the static responses, else n_modes).
    """
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

    Attributes
    ----------
    friction
        (e_f, k_c, e_t, kappa, mu) of Eqs. 21-22 [N/m, 1/m, N/m, -, -].
    preload
        N0, the static normal preload [N].
    static_approach
        delta0, the normal law's static approach [m].
    exponent
        p, the normal law's exponent [-].
    hunt_crossley
        alpha of the normal law's damping N (1 - alpha deta/dt) [s/m].
    viscous
        sigma_2 of the viscous friction S + sigma_2 dxi/dt [N s/m].
    iwan_share
        The share of the tangential contact carried by the Iwan (Maxwell-slip) sliders, 0..1 [-].
    iwan_weights
        The Iwan sliders' slip-limit weights (sum 1) [-], shape (n_sliders,).
    preload_drift
        The preload's relative change over the record [-].
    n_min
        The normal force at or below which the contact carries no friction (it is open) [N].
    unilateral
        Whether the normal contact may open (the power law); False: a bilateral spring that may pull.
    regularization
        How the friction law is read (``none``: as printed, ``slip_limit``; see ``contactid.friction``).
    cubic
        k_3, the normal law's cubic hardening [N/m^3].
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
    """Return the kernels' friction record (e_f, k_c, e_t, kappa, mu, slip_limit).

    slip_limit is 1.0 for the ``slip_limit`` reading of Eq. 21 and 0.0 for the law as printed.

    Parameters
    ----------
    contact
        The contact laws.

    Returns
    -------
    record : np.ndarray
        (e_f, k_c, e_t, kappa, mu, slip_limit) [N/m, 1/m, N/m, -, -, -], shape (6,).
    """
    return np.array([*(float(x) for x in contact.friction), float(slip_limit_flag(contact.regularization))])


def iwan_slip_weights(n: int, spread: float = 0.8) -> np.ndarray:
    """Return the slip limits of n Maxwell-slip sliders as fractions of mu N.

    The thresholds are spread uniformly over [1 - spread, 1 + spread] (relative), each slider with stiffness e_0 / n,
    normalised so that they sum to 1.

    Parameters
    ----------
    n
        The number of sliders.
    spread
        The thresholds' half-range about 1 (relative) [-].

    Returns
    -------
    weights : np.ndarray
        The sliders' slip limits, summing to 1 [-], shape (n,).
    """
    w = np.linspace(1 - spread, 1 + spread, n)
    return w / w.sum()


@dataclass
class SteadyStateLog:
    """How steady state was reached, chunk by chunk.

    Attributes
    ----------
    a1
        The driving-point acceleration's harmonic amplitude |A1| at w of each chunk [m/s^2].
    a3
        Its amplitude |A3| at 3w of each chunk [m/s^2].
    change
        The largest relative change of the two harmonics between chunks, from the second chunk on [-].
    """

    a1: list = field(default_factory=list)
    a3: list = field(default_factory=list)
    change: list = field(default_factory=list)


def force_coefficients(F1: float | np.ndarray, F3: float | None) -> np.ndarray:
    """Return the complex harmonics c_h (h = 1..H) of the excitation, f = sum_h Im(c_h e^{i h w t}).

    [F1, 0, F3] for two amplitudes, or F1 itself (an array) when F3 is None.

    Parameters
    ----------
    F1
        The fundamental's force amplitude [N], or, with ``F3`` None, the complex harmonics c_h themselves [N],
        shape (H,).
    F3
        The third harmonic's force amplitude [N], or None.

    Returns
    -------
    coef : np.ndarray
        The complex harmonics c_1..c_H [N], shape (3,) for two amplitudes, else (H,).
    """
    if F3 is None:
        return np.atleast_1d(np.asarray(F1, dtype=complex))
    return np.array([F1, 0.0, F3], dtype=complex)


class DualSineSimulator:
    """Time integration of the reduced rig model under f = F1 sin(wt) + F3 sin(3wt).

    Or under any periodic force given by its harmonics.

    Parameters
    ----------
    red
        The reduced model.
    contact
        The contact laws.
    zeta
        The modal damping ratio of each reduced coordinate [-], shape (n_r,).
    dt
        The integration time step [s].
    """

    def __init__(self, red: ReducedModel, contact: ContactParameters, zeta: np.ndarray, dt: float):
        self.red = red
        self.contact = contact
        self.zeta = np.asarray(zeta, dtype=float)
        self.dt = float(dt)
        self.fr = friction_record(contact)
        self.iw_w = np.asarray(contact.iwan_weights, dtype=float)
        self.reset()

    def reset(self):
        """Return to rest: zero coordinates, velocities, friction state and Iwan sliders at t = 0.

        No preload drift and no last chunk.
        """
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
        """Return the driving-point accelerance of the stuck linear reduced system at w.

        Parameters
        ----------
        w
            The angular frequency [rad/s].

        Returns
        -------
        accelerance : complex
            The driving-point acceleration per force [m/s^2/N].
        """
        r = self.red
        x = r.force / (r.omega**2 - w**2 + 2j * self.zeta * r.omega * w)
        return complex(-(w**2) * (r.drive @ x))

    def start_from_linear(self, F1: float | np.ndarray, F3: float | None, w: float):
        """Start from the stuck linear system's steady state at t = 0 (force as in ``run``).

        The friction state starts at the stuck spring force.

        Parameters
        ----------
        F1
            The fundamental's force amplitude [N] (a float), or, with ``F3`` None, the excitation's complex
            harmonics c_h (h = 1..H) of f = sum_h Im(c_h e^{i h w t}) [N], shape (H,).
        F3
            The third harmonic's force amplitude [N], or None (``F1`` then holds every harmonic).
        w
            The fundamental angular frequency [rad/s].
        """
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

    def run(
        self,
        F1: float | np.ndarray,
        F3: float | None,
        w: float,
        n_steps: int,
        store_from: int | None = None,
        state: bool = True,
    ) -> dict:
        """Advance ``n_steps`` under the force and return the stored signals.

        The force is f = F1 sin(wt) + F3 sin(3wt), or, with F3 None, f = sum_h Im(F1[h-1] e^{i h w t}) for a complex
        coefficient array F1. The signals are stored from ``store_from`` at the step rate, the coordinates "z" and
        velocities "v" only with ``state`` (a third of the stored numbers: the gap's simulations of a whole record do
        not read them).

        Parameters
        ----------
        F1
            The fundamental's force amplitude [N] (a float), or, with ``F3`` None, the excitation's complex
            harmonics c_h (h = 1..H) of f = sum_h Im(c_h e^{i h w t}) [N], shape (H,).
        F3
            The third harmonic's force amplitude [N], or None (``F1`` then holds every harmonic).
        w
            The fundamental angular frequency [rad/s].
        n_steps
            The number of steps.
        store_from
            The first step stored (None: none is stored).
        state
            Whether the coordinates and velocities are stored too.

        Returns
        -------
        signals : dict
            Over n_store = n_steps - store_from steps: "t" [s], "f" the force [N], "S" and "N" the contact forces
            [N], "xi" and "eta" [m], "dxi" and "deta" their rates [m/s], each of shape (n_store,); "a" the
            generalized accelerations [kg^0.5 m/s^2], shape (n_store, n_r); with ``state`` "z" [kg^0.5 m] and "v"
            [kg^0.5 m/s], shape (n_store, n_r).

        Raises
        ------
        WorkLimitError
            Where the stored signals would pass ``WORK_LIMIT_BYTES`` (raised through ``work_limit_error``).
        """  # noqa: DOC503
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
        """Return the integrator's state (to return to with ``restore``).

        Returns
        -------
        snapshot : tuple
            (z, v, friction state, Iwan sliders, t, drift rate, drift start), copies.
        """
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
        """Return the integrator to a state ``snapshot`` took.

        Parameters
        ----------
        snap
            The state, as ``snapshot`` returned it.
        """
        z, v, state, x_sl, t, rate, t0 = snap
        self.z[:], self.v[:], self.state[:], self.x_sl[:] = z, v, state, x_sl
        self.t, self.drift_rate, self.drift_t0 = t, rate, t0

    def settle(
        self,
        F1: float | np.ndarray,
        F3: float | None,
        w: float,
        chunk_periods: int = 8,
        tol: float = 1e-4,
        min_chunks: int = 3,
        max_chunks: int = 200,
    ) -> tuple[np.ndarray, SteadyStateLog, bool]:
        """Run chunks of ``chunk_periods`` periods until the driving-point harmonics at w and 3w settle.

        They settle when they change by less than ``tol`` (relative) from one chunk to the next. The last chunk's
        signals (``run``'s dict) stay in ``last_chunk`` (without the coordinates and velocities), so that a settled
        response can be recorded from them.

        Parameters
        ----------
        F1
            The fundamental's force amplitude [N] (a float), or, with ``F3`` None, the excitation's complex
            harmonics c_h (h = 1..H) of f = sum_h Im(c_h e^{i h w t}) [N], shape (H,).
        F3
            The third harmonic's force amplitude [N], or None (``F1`` then holds every harmonic).
        w
            The fundamental angular frequency [rad/s].
        chunk_periods
            The periods per chunk.
        tol
            The largest relative change of the harmonics between chunks that counts as settled [-].
        min_chunks
            The fewest chunks run.
        max_chunks
            The most chunks run.

        Returns
        -------
        harmonics : np.ndarray
            [A1, A3], the driving-point acceleration's complex harmonics at w and 3w of the last chunk [m/s^2],
            shape (2,).
        log : SteadyStateLog
            How steady state was reached.
        converged : bool
            Whether the harmonics settled within ``max_chunks``.
        """
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
