"""The virtual rig's response control: the dual-sine test's force amplitudes tuned to the target response.

F1 and F3 are tuned until the driving point's acceleration harmonics at w and 3w reach their targets (Broyden's
method, Section 3), on ``rig.simulator.DualSineSimulator``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# progress: the logger of the response control's iterations, contactid.rig.nonlinear's (the name its lines carry)
from .nonlinear import progress
from .simulator import DualSineSimulator, SteadyStateLog


@dataclass
class ControlResult:
    """Response control's outcome: the force amplitudes found, the harmonics they give, the iteration's history.

    The harmonics are the driving-point acceleration's amplitudes at w and 3 w; unconverged, the forces and the
    harmonics are the last iteration's.

    Attributes
    ----------
    F1
        Force amplitude at w [N].
    F3
        Force amplitude at 3 w [N].
    A1
        Driving-point acceleration amplitude at w that F1, F3 give [m/s^2].
    A3
        Driving-point acceleration amplitude at 3 w that F1, F3 give [m/s^2].
    converged
        Whether the response settled on the targets within the tolerance.
    history
        One tuple (F1 [N], F3 [N], A1 [m/s^2], A3 [m/s^2], steady) per iteration, in order; steady: whether the
        response had settled (a response that was not finite gives NaN or inf amplitudes).
    steady_state
        How the last iteration's run of the simulator approached steady state (``SteadyStateLog``: A1, A3 of
        each chunk and their change).
    """

    F1: float
    F3: float
    A1: float
    A3: float
    converged: bool
    history: list
    steady_state: SteadyStateLog


def _log_unsteady_stop(it: int, F: np.ndarray, A: np.ndarray, unsteady: int) -> None:
    """Log that the control stops at iteration ``it`` (from 0), not steady for ``unsteady`` iterations.

    F holds the force amplitudes (N), A the response amplitudes (m/s^2).
    """
    progress.info(
        "response control %d: F1 = %.4g N, F3 = %.4g N -> A1 = %.4g, A3 = %.4g m/s^2; not steady for "
        "%d iterations: the motion does not settle into a periodic state, the control stops here",
        it + 1,
        F[0],
        F[1],
        A[0],
        A[1],
        unsteady,
    )


def _log_iteration(it: int, F: np.ndarray, A: np.ndarray, target: np.ndarray, ok: bool) -> None:
    """Log iteration ``it`` (from 0) of the control: force (N), response and targets (m/s^2), steady or not."""
    progress.info(
        "response control %d: F1 = %.4g N, F3 = %.4g N -> A1 = %.4g (target %.4g), A3 = %.4g (target %.4g) m/s^2%s",
        it + 1,
        F[0],
        F[1],
        A[0],
        target[0],
        A[1],
        target[1],
        "" if ok else ", not yet steady",
    )


def _backed_off_force(sim: DualSineSimulator, F: np.ndarray, good: tuple | None, w: float, it: int) -> np.ndarray:
    """Return the force amplitudes (N) to try after the trial force F of iteration ``it`` gave no finite response.

    Half of F from the stuck linear steady state when no force has given a finite response yet, else halfway back to
    the last force that did (``good``: force and simulator state), from that force's state.
    """
    progress.info(
        "response control %d: F1 = %.4g N, F3 = %.4g N -> the response is not finite; halving the step back",
        it + 1,
        F[0],
        F[1],
    )
    if good is None:
        F = 0.5 * F
        sim.start_from_linear(F[0], F[1], w)
    else:
        F = 0.5 * (F + good[0])
        sim.restore(good[1])
    return F


def _broyden_jacobian(J: np.ndarray, dF: np.ndarray, dA: np.ndarray) -> np.ndarray:
    """Return Broyden's rank-one update of the Jacobian d|A|/dF (m/s^2/N).

    From the last change of the force dF (N) and of the response dA (m/s^2); J itself when the force did not change.
    """
    if dF @ dF > 0:
        J = J + np.outer(dA - J @ dF, dF) / (dF @ dF)
    return J


def _next_force(J: np.ndarray, F: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Return the next force amplitudes (N): the Newton step on the Jacobian J (m/s^2/N) for the residual r (m/s^2).

    The step is taken on J's diagonal where J is singular, each amplitude kept within a factor of 3 of F.
    """
    try:
        step = np.linalg.solve(J, -r)
    except np.linalg.LinAlgError:
        step = -r / np.diag(J)
    F_new = F + step
    return np.clip(F_new, 0.3 * F, 3.0 * F)  # keep each update within a factor of 3


def control_response(
    sim: DualSineSimulator,
    target_a1: float,
    target_a3: float,
    w: float,
    tol: float = 1e-3,
    max_iter: int = 40,
    max_unsteady: int = 12,
) -> ControlResult:
    """Tune F1, F3 until the driving-point acceleration harmonics at w and 3w equal the targets.

    Broyden's method on (F1, F3) -> (|A1|, |A3|), started from the stuck linear system's FRF. A trial force whose
    response is not finite (violent impacts beyond what the explicit integrator resolves) is halved back towards the
    last force that gave a finite response, from that force's state. A response that has not settled for
    ``max_unsteady`` iterations in a row (impacts that keep the motion from becoming periodic) ends the control
    there, unconverged, as a test engineer would stop (the blind benchmark's contact-separation items ran all 40
    iterations on lc3, 22 s each, without settling).

    Parameters
    ----------
    sim
        The rig's dual-sine simulator; it is left in the state of the last force tried.
    target_a1
        Target amplitude of the driving point's acceleration at w [m/s^2].
    target_a3
        Target amplitude of the driving point's acceleration at 3 w [m/s^2].
    w
        Excitation (angular) frequency [rad/s].
    tol
        Largest relative misfit of either harmonic to its target that counts as converged [-].
    max_iter
        Most iterations (each one settled run of the simulator).
    max_unsteady
        Iterations in a row without a settled response after which the control stops, unconverged.

    Returns
    -------
    result : ControlResult
        The force amplitudes found (or the last tried, unconverged), the harmonics they give and the history.
    """
    h1, h3 = abs(sim.linear_frf(w)), abs(sim.linear_frf(3 * w))
    target = np.array([target_a1, target_a3])
    F = target / np.array([h1, h3])
    J = np.diag([h1, h3])
    sim.start_from_linear(F[0], F[1], w)
    history = []
    prev = None
    log = None
    good = None  # (F, simulator state) of the last finite response
    unsteady = 0
    for it in range(max_iter):
        c, log, ok = sim.settle(F[0], F[1], w)
        A = np.abs(c)
        history.append((float(F[0]), float(F[1]), float(A[0]), float(A[1]), bool(ok)))
        unsteady = 0 if ok else unsteady + 1
        if unsteady >= max_unsteady and np.all(np.isfinite(A)):
            _log_unsteady_stop(it, F, A, unsteady)
            break
        if not np.all(np.isfinite(A)) or not np.all(np.isfinite(sim.z)):
            F = _backed_off_force(sim, F, good, w, it)
            continue
        good = (F.copy(), sim.snapshot())
        r = A - target
        _log_iteration(it, F, A, target, ok)
        if ok and np.max(np.abs(r) / target) < tol:
            return ControlResult(float(F[0]), float(F[1]), float(A[0]), float(A[1]), True, history, log)
        if prev is not None:
            J = _broyden_jacobian(J, F - prev[0], A - prev[1])
        prev = (F.copy(), A.copy())
        F = _next_force(J, F, r)
    c = history[-1]
    return ControlResult(c[0], c[1], c[2], c[3], False, history, log)
