"""The chain redone with a candidate effect in the model, and the gap between a simulation and a record.

For a candidate with parameters theta the whole identification is redone with the effect in the
model, on the calibration case only: the contact forces by inverse identification with the
augmented structure (extra damping, transducer masses) on the augmented record (channel delays
removed), the friction law polished from the chain's fit with the augmented law (viscous term,
Iwan share), then the forward simulation (``evaluate``). The search for theta is ``calibration``'s.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from numba import njit

from ..beam_modes import all_modes
from ..friction import initial_stiffness, iwan_force, valanis_friction_force
from ..friction_problem import FitProblem, least_squares_polish
from ..harmonics import periodic_grid
from ..identification import InverseHarmonics, inverse_harmonics
from ..modal_damping import modal_damping_vector
from ..rig.nonlinear import iwan_slip_weights
from .model import NONE, Augmentation, IdentifiedModel, fe_model
from .numerics import DEFAULT, Numerics
from .records import RecordHarmonics
from .simulation import SimResult, simulate

if TYPE_CHECKING:
    from collections.abc import Callable, Hashable

    from ..beam_model import FEModel

# ------------------------------------------------------------------------------------------
# the gap
# ------------------------------------------------------------------------------------------


def gap_residual(sim: SimResult, rec: RecordHarmonics, n_harmonics: int) -> np.ndarray:
    """Return the residual between a simulation and a record, scaled by the record's acceleration harmonics' norm.

    The sensors' harmonics 1..H of the whole record, and the change from the first to the last third (drift); both
    divided by the norm of the record's acceleration harmonics 1..H.

    Parameters
    ----------
    sim
        The simulation of the record (its ``first`` and ``last`` thirds; ``first`` None: the simulation has no drift).
    rec
        One load case's record in harmonics.
    n_harmonics
        H, the harmonics compared.

    Returns
    -------
    residual : np.ndarray
        The complex scaled residual [-], shape (2 n_sensors H,): (A_sim - A_rec) over sensors and harmonics 1..H
        (sensor-major), then the simulated minus the recorded drift, likewise.
    """
    H = n_harmonics
    scale = np.linalg.norm(rec.acceleration[:, :H])
    r = [(sim.acceleration[:, :H] - rec.acceleration[:, :H]).ravel()]
    d_meas = (rec.last - rec.first)[:, :H]
    d_sim = (sim.last - sim.first)[:, :H] if sim.first is not None else np.zeros_like(d_meas)
    r.append((d_sim - d_meas).ravel())
    return np.concatenate(r) / scale


def gap_value(residual: np.ndarray) -> float:
    """Return the gap: the norm of the scaled residual, i.e. ||A_sim - A_rec|| / ||A_rec||.

    The drift part is added in quadrature.

    Parameters
    ----------
    residual
        The scaled residual (``gap_residual``) [-], shape (n_r,), complex.

    Returns
    -------
    gap : float
        The gap [-].
    """
    return float(np.linalg.norm(residual))


# ------------------------------------------------------------------------------------------
# identification with an augmented model
# ------------------------------------------------------------------------------------------


def augmented_zeta(fe: FEModel, damping: Sequence[float], extra: float) -> np.ndarray:
    """Return the damping ratio of every FE mode (``modal_damping_vector``) plus ``extra`` on the structural modes.

    The structural (beam) modes are those with less than half their kinetic energy in the block.

    Parameters
    ----------
    fe
        The assembled FE model.
    damping
        The identified structural modes' damping ratios, by order [-].
    extra
        The damping ratio added to the structural modes [-].

    Returns
    -------
    zeta : np.ndarray
        The damping ratio of every FE mode, sorted by frequency [-], shape (n_dof,).
    """
    zeta = modal_damping_vector(fe, np.asarray(damping))
    if extra:
        zeta[all_modes(fe).block_energy_fraction < 0.5] += extra
    return zeta


def deskewed(rec: RecordHarmonics, delays: Sequence[float], gains: Sequence[float] = ()) -> np.ndarray:
    """Return the record's acceleration harmonics with per-channel delays and sensitivity factors removed.

    Parameters
    ----------
    rec
        One load case's record in harmonics.
    delays
        Each acceleration channel's delay on the force [s], one per sensor; empty: none.
    gains
        Each channel's sensitivity factor (it reads g times its acceleration) [-], one per sensor; empty: none.

    Returns
    -------
    acceleration : np.ndarray
        The corrected complex acceleration harmonics [m/s^2], shape (n_sensors, n_h), n_h the record's harmonics.
    """
    A = rec.acceleration
    if len(delays):
        h = np.arange(1, A.shape[1] + 1)
        A = A * np.exp(1j * np.outer(np.asarray(delays, float), 2 * np.pi * rec.f0 * h))
    if len(gains):
        A = A / np.asarray(gains, float)[:, None]
    return A


class _Memo:
    """A small memo of pure results keyed by value, plus objects (records, forces) that the key names by identity.

    The entry keeps those objects alive, so an id is never reused while its entry exists.

    Parameters
    ----------
    size
        How many entries it keeps (the oldest is dropped first).
    """

    def __init__(self, size: int = 64):
        self.size, self.store = size, {}

    def get(self, key: Hashable, compute: Callable[[], tuple[Any, Any]], enabled: bool = True) -> Any:
        """Return the result of ``compute``, from the memo where ``enabled``; otherwise computed anew and not stored.

        Parameters
        ----------
        key
            The entry's key.
        compute
            Returns (result, the objects the key names by identity).
        enabled
            Whether to use the memo (``Numerics.memo``).

        Returns
        -------
        result : Any
            The first element of what ``compute`` returns.
        """
        if not enabled:
            return compute()[0]
        hit = self.store.get(key)
        if hit is None:
            if len(self.store) >= self.size:
                self.store.pop(next(iter(self.store)))
            hit = self.store[key] = compute()
        return hit[0]


_FORCES = _Memo()
_FRICTION = _Memo()


def identified_forces(
    model: IdentifiedModel, aug: Augmentation, rec: RecordHarmonics, memo: bool = True
) -> InverseHarmonics:
    """Return the contact forces of a record by inverse identification with the augmented model.

    Memoised where ``memo`` (``Numerics.memo``): the candidates that leave the structure, its damping and the channels
    as they are reuse it.

    Parameters
    ----------
    model
        The identified model (the chain's, or a candidate's).
    aug
        The effects added to the model (``NONE``: as the chain left it).
    rec
        One load case's record in harmonics.
    memo
        Whether to memoise (``Numerics.memo``).

    Returns
    -------
    forces : InverseHarmonics
        The identified contact forces and motion, in harmonics.
    """
    key = (
        model.structure_with(aug),
        model.test_damping,
        aug.extra_damping,
        tuple(aug.delays),
        tuple(aug.gains),
        id(rec),
    )

    def compute():
        fe = fe_model(model, aug)
        zeta = augmented_zeta(fe, model.test_damping, aug.extra_damping)
        return inverse_harmonics(fe, zeta, rec.force, deskewed(rec, aug.delays, aug.gains), rec.f0), rec

    return _FORCES.get(key, compute, memo)


@njit(cache=True)
def _iwan_periodic(xi, N, e_f, k_c, mu, weights, periods):
    n = weights.size
    x_sl = np.zeros(n)
    out = np.zeros(xi.size)
    no_flags = np.empty(0, dtype=np.int8)
    for _ in range(periods):
        for t in range(xi.size):
            if N[t] <= 0.0:
                for i in range(n):
                    x_sl[i] = xi[t]
                out[t] = 0.0
                continue
            out[t] = iwan_force(xi[t], x_sl, weights, initial_stiffness(N[t], e_f, k_c), mu * N[t], no_flags)
    return out


def law_friction_force(
    xi: np.ndarray, xi_dot: np.ndarray, N: np.ndarray, params: np.ndarray, aug: Augmentation, regularization: str
) -> np.ndarray:
    """Return S of the (augmented) friction law over one period: (1 - s) Valanis + s Iwan + sigma_2 dxi/dt.

    Parameters
    ----------
    xi
        The tangential motion over one period [m], shape (m,).
    xi_dot
        Its rate [m/s], shape (m,).
    N
        The total normal force [N], shape (m,); the Valanis law sees it clipped at 1 mN where the contact would open.
    params
        The law's parameters e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5,) or (n_sets, 5).
    aug
        The augmentation: its Iwan share s and viscous coefficient sigma_2 are read.
    regularization
        The reading of Eq. 21 (see ``contactid.friction``).

    Returns
    -------
    S : np.ndarray
        The friction force [N], shape (n_sets, m) (n_sets 1 for one parameter set).
    """
    Nc = np.maximum(N, 1e-3)
    S = valanis_friction_force(xi, Nc, np.atleast_2d(params), regularization=regularization)
    if aug.iwan_share:
        p = np.atleast_2d(params)
        iw = np.array([_iwan_periodic(xi, N, q[0], q[1], q[4], iwan_slip_weights(16), 3) for q in p])
        S = (1 - aug.iwan_share) * S + aug.iwan_share * iw
    if aug.viscous:
        S = S + aug.viscous * np.where(N > 0, xi_dot, 0.0)[None, :]
    return S


class _AugmentedProblem(FitProblem):
    def __init__(self, xi, xi_dot, N, S, bounds, aug, regularization):
        super().__init__(xi, N, S, bounds, regularization)
        self.xi_dot, self.aug = xi_dot, aug

    def residuals(self, params):
        S = law_friction_force(self.xi, self.xi_dot, self.N, params, self.aug, self.regularization)
        S = S - S.mean(axis=1, keepdims=True)
        return (S - self.S) / self.scale


def contact_grids(forces: InverseHarmonics, f0: float, preload: float, m: int) -> dict:
    """Return one period of the identified xi, xi_dot, N (total), S (mean removed), eta and eta_dot on m points.

    Parameters
    ----------
    forces
        The identified contact forces and motion, in harmonics.
    f0
        The drive frequency [Hz].
    preload
        The static normal preload N0 [N], added to the dynamic normal force.
    m
        The points of the period.

    Returns
    -------
    grids : dict
        xi [m], xi_dot [m/s], N [N], S [N], eta [m] and eta_dot [m/s], each of shape (m,).
    """
    return {
        "xi": periodic_grid(forces.xi, f0, m)[0],
        "xi_dot": periodic_grid(forces.xi_dot, f0, m)[0],
        "N": preload + periodic_grid(forces.N_dyn, f0, m)[0],
        "S": periodic_grid(forces.S, f0, m)[0],
        "eta": periodic_grid(forces.eta, f0, m)[0],
        "eta_dot": periodic_grid(forces.eta_dot, f0, m)[0],
    }


def refit_friction(
    model: IdentifiedModel,
    aug: Augmentation,
    forces: InverseHarmonics,
    f0: float,
    bounds: Sequence[Sequence[float]],
    grid: int = 512,
    memo: bool = True,
) -> tuple[np.ndarray, float]:
    """Polish the friction law (with the augmentation's terms) from the chain's fit to the identified forces.

    Memoised where ``memo`` (``Numerics.memo``): a candidate that changes neither the forces nor the law gets the same
    polish.

    Parameters
    ----------
    model
        The identified model (the chain's, or a candidate's): its friction law is the start.
    aug
        The effects added to the model (``NONE``: as the chain left it).
    forces
        The identified contact forces and motion, in harmonics (``identified_forces``).
    f0
        The drive frequency [Hz].
    bounds
        The search bounds (low, high) of e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5, 2) (config
        ``friction.bounds``, ``FitSettings.bounds``).
    grid
        The points of the period the law is fitted on.
    memo
        Whether to memoise (``Numerics.memo``).

    Returns
    -------
    params : np.ndarray
        The polished e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5,).
    nrmse : float
        The NRMSE of S, relative to the rms of the identified S [-].
    """
    law = (aug.iwan_share, aug.viscous, aug.preload_drift)
    key = (
        model.friction,
        model.preload,
        model.regularization,
        law,
        id(forces),
        f0,
        tuple(map(tuple, np.atleast_2d(bounds))),
        grid,
    )

    def compute():
        # a drifting preload: the record's harmonics see the mean preload over the record
        g = contact_grids(forces, f0, model.preload * (1.0 + 0.5 * aug.preload_drift), grid)
        prob = _AugmentedProblem(g["xi"], g["xi_dot"], g["N"], g["S"], bounds, aug, model.regularization)
        u0 = np.clip(prob.unit(np.asarray(model.friction))[0], 1e-6, 1 - 1e-6)
        # looser than the chain's own polish (1e-10, 1e-12): the law's parameters move by about 1e-8 of their ranges,
        # far below what the gap resolves, and a refit takes a fifth fewer evaluations of the law
        u, ssr, _ = least_squares_polish(prob, u0, xtol=1e-8, ftol=1e-10)
        return (prob.physical(u)[0], float(np.sqrt(ssr / grid))), forces

    return _FRICTION.get(key, compute, memo)


# ------------------------------------------------------------------------------------------
# the chain redone with an augmentation
# ------------------------------------------------------------------------------------------


def evaluate(
    model: IdentifiedModel,
    aug: Augmentation,
    rec: RecordHarmonics,
    bounds: Sequence[Sequence[float]] | None,
    n_harmonics: int,
    refit: bool = True,
    start: SimResult | None = None,
    polish: bool = True,
    numerics: Numerics = DEFAULT,
) -> tuple[float, IdentifiedModel, SimResult, float]:
    """Redo the chain with ``aug`` on one record: the gap, the model with refitted friction, its simulation, the misfit.

    Parameters
    ----------
    model
        The identified model (the chain's, or a candidate's).
    aug
        The effects added to the model (``NONE``: as the chain left it).
    rec
        One load case's record in harmonics.
    bounds
        The search bounds (low, high) of e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5, 2) (config
        ``friction.bounds``, ``FitSettings.bounds``); None without ``refit``.
    n_harmonics
        H, the harmonics compared (the harmonic balance uses 2 H).
    refit
        Whether to redo the inverse identification and refit the friction law (False: the model's law as it is).
    start
        A neighbouring simulation of the record to warm-start the steady state from (None: none).
    polish
        See ``simulate`` (False: the harmonic-balance state itself, where it converges).
    numerics
        The steady state's method and settling tolerance and the memos (``numerics.Numerics``).

    Returns
    -------
    gap : float
        The gap ``gap_value`` [-].
    model : IdentifiedModel
        The model with the refitted friction law (``model`` itself without ``refit``).
    sim : SimResult
        The simulation of the record.
    misfit : float
        The refit's NRMSE of S [-]; NaN without ``refit``.
    """
    misfit = float("nan")
    if refit:
        forces = identified_forces(model, aug, rec, memo=numerics.memo)
        fr, misfit = refit_friction(model, aug, forces, rec.f0, bounds, memo=numerics.memo)
        model = model.with_friction(fr)
    sim = simulate(model, aug, rec, start=start, hb_harmonics=2 * n_harmonics, polish=polish, numerics=numerics)
    return gap_value(gap_residual(sim, rec, n_harmonics)), model, sim, misfit


def baseline(
    model: IdentifiedModel, rec: RecordHarmonics, n_harmonics: int, numerics: Numerics = DEFAULT
) -> tuple[float, SimResult]:
    """Return the gap and the simulation of the identified model as the chain left it (no effect, no refit) on a record.

    Parameters
    ----------
    model
        The identified model (the chain's, or a candidate's).
    rec
        One load case's record in harmonics.
    n_harmonics
        H, the harmonics compared.
    numerics
        The steady state's method and settling tolerance and the memos (``numerics.Numerics``).

    Returns
    -------
    gap : float
        The gap ``gap_value`` [-].
    sim : SimResult
        The simulation of the record.
    """
    g, _, sim, _ = evaluate(model, NONE, rec, None, n_harmonics, refit=False, numerics=numerics)
    return g, sim
