"""The chain redone with a candidate effect in the model, and the gap between a simulation and a record.

For a candidate with parameters theta the whole identification is redone with the effect in the
model, on the calibration case only: the contact forces by inverse identification with the
augmented structure (extra damping, transducer masses) on the augmented record (channel delays
removed), the friction law polished from the chain's fit with the augmented law (viscous term,
Iwan share), then the forward simulation (``evaluate``). The search for theta is ``calibration``'s.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..beam_model import all_modes
from ..friction import initial_stiffness, iwan_force, valanis_friction_force
from ..friction_fit import FitProblem, least_squares_polish
from ..harmonics import periodic_grid
from ..identification import InverseHarmonics, inverse_harmonics, modal_damping_vector
from ..rig.nonlinear import iwan_slip_weights
from .model import NONE, Augmentation, IdentifiedModel, fe_model
from .numerics import DEFAULT, Numerics
from .records import RecordHarmonics
from .simulation import SimResult, simulate

# ------------------------------------------------------------------------------------------
# the gap
# ------------------------------------------------------------------------------------------


def gap_residual(sim: SimResult, rec: RecordHarmonics, n_harmonics: int) -> np.ndarray:
    """Residual (complex, scaled by the record's rms acceleration harmonic norm): the sensors'
    harmonics 1..H of the whole record, and the change from the first to the last third (drift)."""
    H = n_harmonics
    scale = np.linalg.norm(rec.acceleration[:, :H])
    r = [(sim.acceleration[:, :H] - rec.acceleration[:, :H]).ravel()]
    d_meas = (rec.last - rec.first)[:, :H]
    d_sim = (sim.last - sim.first)[:, :H] if sim.first is not None else np.zeros_like(d_meas)
    r.append((d_sim - d_meas).ravel())
    return np.concatenate(r) / scale


def gap_value(residual: np.ndarray) -> float:
    """The gap: rms of the scaled residual over its entries' norm, i.e. ||A_sim - A_rec|| / ||A_rec||
    (with the drift part added in quadrature)."""
    return float(np.linalg.norm(residual))


# ------------------------------------------------------------------------------------------
# identification with an augmented model
# ------------------------------------------------------------------------------------------


def augmented_zeta(fe, damping, extra: float) -> np.ndarray:
    """Damping ratio of every FE mode (``modal_damping_vector``) plus ``extra`` on the structural (beam) modes."""
    zeta = modal_damping_vector(fe, np.asarray(damping))
    if extra:
        zeta[all_modes(fe).block_energy_fraction < 0.5] += extra
    return zeta


def deskewed(rec: RecordHarmonics, delays, gains=()) -> np.ndarray:
    """The record's acceleration harmonics with per-channel delays (s) and sensitivity factors (``gains``: each channel
    reads g times its acceleration) removed."""
    A = rec.acceleration
    if len(delays):
        h = np.arange(1, A.shape[1] + 1)
        A = A * np.exp(1j * np.outer(np.asarray(delays, float), 2 * np.pi * rec.f0 * h))
    if len(gains):
        A = A / np.asarray(gains, float)[:, None]
    return A


class _Memo:
    """A small memo of pure results keyed by value, plus objects (records, forces) that the key names by
    identity: the entry keeps them alive, so an id is never reused while its entry exists."""

    def __init__(self, size: int = 64):
        self.size, self.store = size, {}

    def get(self, key, compute, enabled: bool = True):
        """The result of ``compute`` (which returns (result, objects the key names)), from the memo where ``enabled``
        (``Numerics.memo``); otherwise computed anew and not stored."""
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
    """Contact forces of a record by inverse identification with the augmented model (memoised where ``memo``,
    ``Numerics.memo``: the candidates that leave the structure, its damping and the channels as they are reuse it)."""
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


def law_friction_force(xi, xi_dot, N, params, aug: Augmentation, regularization: str) -> np.ndarray:
    """S (N) of the (augmented) friction law over one period: (1 - s) Valanis + s Iwan + sigma_2 dxi/dt
    (params: e_f, k_c, e_t, kappa, mu; N total, clipped at 1 mN where the contact would open; regularization:
    the reading of Eq. 21, see ``contactid.friction``)."""
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
    """One period of the identified xi, xi_dot, N (total) and S (mean removed) on m points."""
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
    bounds,
    grid: int = 512,
    memo: bool = True,
) -> tuple[np.ndarray, float]:
    """The friction law (with the augmentation's terms) polished from the chain's fit to the
    identified forces; returns (e_f, k_c, e_t, kappa, mu) and the NRMSE of S (memoised where ``memo``,
    ``Numerics.memo``: a candidate that changes neither the forces nor the law gets the same polish)."""
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
    bounds,
    n_harmonics: int,
    refit: bool = True,
    start: SimResult | None = None,
    polish: bool = True,
    numerics: Numerics = DEFAULT,
):
    """Redo the chain with ``aug`` on one record: (gap, model with refitted friction, simulation, misfit).
    ``start``: a neighbouring simulation of the record to warm-start the steady state from; ``polish``: see
    ``simulate`` (False: the harmonic-balance state itself, where it converges); ``numerics``: the steady state's
    method and settling tolerance and the memos (``numerics.Numerics``)."""
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
    """The identified model as the chain left it (no effect, no refit) on one record."""
    g, _, sim, _ = evaluate(model, NONE, rec, None, n_harmonics, refit=False, numerics=numerics)
    return g, sim
