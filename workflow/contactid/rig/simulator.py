"""Virtual rig, time integration: the reduced model driven by a periodic force, run to its steady state.

``DualSineSimulator`` integrates the equations of ``rig.nonlinear``'s docstring (the reduced model and the contact laws
built there) under f = F1 sin(wt) + F3 sin(3wt), or any periodic force given by its harmonics (``force_coefficients``),
with the kernels of ``rig.integrator``: chunk by chunk until the driving point's harmonics settle (``SteadyStateLog``),
its stored signals bounded by ``rig.nonlinear.WORK_LIMIT_BYTES``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..harmonics import harmonic_amplitudes, periodic_harmonics
from .integrator import KernelContact, KernelDrive, KernelModel, KernelRecord, integrate
from .nonlinear import (
    WORK_LIMIT_BYTES,
    ContactParameters,
    ReducedModel,
    friction_record,
    gib,
    record_bytes,
    stiffest_mode,
    work_limit_error,
)


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
