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

The kernels of the time step (the contact laws and ``integrate``) are in ``rig.integrator``, the simulator that
runs them (``DualSineSimulator``) in ``rig.simulator``, the response control (``control_response``) in
``rig.control``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from ..beam_model import FEModel, shortening_matrix
from ..beam_modes import all_modes, fix_signs
from ..friction import slip_limit_flag

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
one harmonic-balance grid (``rig.periodic_response.grid_bytes``) may take. With the job's own memory (the largest job
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
