"""Undamped modes of the structure's finite-element model, and its natural frequencies against the contact springs.

The modes of an assembled :class:`~contactid.beam_model.FEModel` (the generalised eigenproblem K phi = omega^2 M phi),
mass-normalised, their signs fixed so that they are reproducible, and computed once per model object. The structural
modes are the beam's (the paper's modes 1, 2, 3, ...): the hanging block's suspension modes are left out.
``ContactFrequencyMap`` gives the structural natural frequencies as a function of the contact stiffnesses (k_t, k_n)
and of a scale on Young's modulus, solved in a Ritz basis for the stiffness fit, which evaluates one structure many
times.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .beam_model import FEModel, assemble
from .parameters import StructureParameters


@dataclass(frozen=True)
class Modes:
    """Undamped modes of an :class:`FEModel`.

    Attributes
    ----------
    frequencies_hz
        Natural frequencies [Hz], shape (n_modes,).
    shapes
        Mode shapes, mass-normalised (shapes.T @ M @ shapes = I) [kg^-0.5] on the translational dofs (rad/(kg^0.5 m)
        on the slopes), shape (n_dof, n_modes).
    block_energy_fraction
        Share of each mode's kinetic energy carried by the hanging block's own coordinates [-], shape (n_modes,).
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    block_energy_fraction: np.ndarray


def fix_signs(vectors: np.ndarray) -> np.ndarray:
    """Return the columns with their largest-magnitude entry made positive.

    So that eigenvectors (whose sign the solver leaves free, and may flip between processes) are reproducible.

    Parameters
    ----------
    vectors
        Vectors as columns, shape (n, n_vectors); in the package mass-normalised mode shapes [kg^-0.5] (any unit
        works).

    Returns
    -------
    vectors : np.ndarray
        The same columns, each possibly negated [unit of vectors], shape (n, n_vectors).
    """
    idx = np.argmax(np.abs(vectors), axis=0)
    return vectors * np.sign(vectors[idx, np.arange(vectors.shape[1])])


_MODES: dict = {}


def all_modes(model: FEModel) -> Modes:
    """Return all undamped modes, sorted by frequency, mass-normalised.

    Computed once per model object: the identification and the gap diagnosis ask for the same model's modes many
    times.

    Parameters
    ----------
    model
        The assembled model.

    Returns
    -------
    modes : Modes
        Every mode of the model (n_modes = n_dof), suspension modes of the block included.
    """
    key = id(model)
    hit = _MODES.get(key)
    if hit is not None and hit[0]() is model:
        return hit[1]
    modes = _all_modes(model)
    if len(_MODES) > 64:
        _MODES.clear()
    _MODES[key] = (weakref.ref(model), modes)
    return modes


def _all_modes(model: FEModel) -> Modes:
    lam, vec = scipy.linalg.eigh(model.stiffness, model.mass)
    lam = np.clip(lam, 0.0, None)
    vec = fix_signs(vec)
    # share of the (unit, mass-normalised) kinetic energy carried by the block
    p = model.params
    frac = (
        p.block_mass * ((model.block_lateral_vector @ vec) ** 2 + (model.block_axial_vector @ vec) ** 2)
        + p.block_inertia * vec[model.thetas_dof] ** 2
    )
    return Modes(np.sqrt(lam) / (2 * np.pi), vec, frac)


def structural_modes(model: FEModel, n_modes: int | None = None, max_block_fraction: float = 0.5) -> Modes:
    """Return the modes of the beam (the paper's modes 1, 2, 3, ...), sorted by frequency.

    Suspension modes of the hanging block (pendulum swing, bounce on the string),
    whose kinetic energy lies mostly in y_s and theta_s, are left out: they sit
    near 1 Hz and 10 Hz, far below the band of interest, and no beam sensor
    sees them.

    Parameters
    ----------
    model
        The assembled model.
    n_modes
        How many modes, lowest first; None: every structural mode.
    max_block_fraction
        A mode whose kinetic energy share on the block's own coordinates reaches this is a suspension mode [-].

    Returns
    -------
    modes : Modes
        The structural modes.

    Raises
    ------
    ValueError
        When the model has fewer than ``n_modes`` structural modes.
    """
    m = all_modes(model)
    keep = np.flatnonzero(m.block_energy_fraction < max_block_fraction)
    if n_modes is not None:
        if len(keep) < n_modes:
            raise ValueError(f"the model has only {len(keep)} structural modes, {n_modes} requested")
        keep = keep[:n_modes]
    return Modes(m.frequencies_hz[keep], m.shapes[:, keep], m.block_energy_fraction[keep])


def natural_frequencies(params: StructureParameters, n_modes: int = 3) -> np.ndarray:
    """Return the first structural natural frequencies of the linear system with the contact springs of Eq. (13).

    Parameters
    ----------
    params
        The structure.
    n_modes
        How many frequencies, lowest first.

    Returns
    -------
    frequencies : np.ndarray
        Natural frequencies [Hz], ascending, shape (n_modes,).
    """
    return structural_modes(assemble(params), n_modes).frequencies_hz


RITZ_MODES = 20  # modes of K_0 in ContactFrequencyMap's basis (with the two static contact shapes: within 3e-9 of
# the full eigenproblem over k_t 1e5-1e9 and k_n 1e5-1e11 N/m on the paper's structure, at a fifteenth of its cost)


class ContactFrequencyMap:
    """Natural frequencies as a function of the contact stiffnesses (k_t, k_n) for one structure.

    Reuses the assembly: K = K_0 + k_t xi xi^T + k_n eta eta^T. Used in the stiffness fit, where the structure is
    evaluated many times. The contact springs are a rank-2 change of K_0, so the eigenproblem is solved in a Ritz basis:
    the lowest RITZ_MODES modes of (K_0, M) and the static shapes K_0^-1 xi, K_0^-1 eta (the contact's constraint
    modes), M-orthonormal. Where K_0 is singular or the model too small, the full eigenproblem is solved.

    Parameters
    ----------
    params
        The structure (its own k_t, k_n are replaced at each call).
    n_modes
        How many structural frequencies a call returns, lowest first.
    max_block_fraction
        A mode whose kinetic energy share on the block's own coordinates reaches this is a suspension mode, left out
        (as in ``structural_modes``) [-].
    """

    def __init__(self, params: StructureParameters, n_modes: int = 3, max_block_fraction: float = 0.5):
        self.model = m = assemble(params)
        self.n_modes = n_modes
        self.max_block_fraction = max_block_fraction
        self._k0 = m.stiffness_without_contact
        self._ke = None  # K_E and its Ritz projection, made on the first call with a stiffness scale (_stiffness_part)
        self._xx = np.outer(m.xi_vector, m.xi_vector)
        self._ee = np.outer(m.eta_vector, m.eta_vector)
        self._basis = None
        n0 = min(RITZ_MODES, m.n_dof - 2)
        if n0 >= n_modes + 6:
            try:
                _, phi = scipy.linalg.eigh(self._k0, m.mass, subset_by_index=[0, n0 - 1])
                static = np.linalg.solve(self._k0, np.column_stack([m.xi_vector, m.eta_vector]))
                V = np.column_stack([phi, _m_orthonormal_complement(phi, static, m.mass)])
                self._basis = (V, V.T @ self._k0 @ V, V.T @ m.xi_vector, V.T @ m.eta_vector)
            except np.linalg.LinAlgError:
                self._basis = None

    def __call__(self, k_t: float, k_n: float, stiffness_scale: float = 1.0) -> np.ndarray:
        """Return the structural natural frequencies with contact springs k_t, k_n and a scaled Young's modulus.

        Solved in the Ritz basis of the structure's own modes: within 1e-8 of the full eigenproblem for scales of
        0.9-1.1 (tests/test_beam_modes.py).

        Parameters
        ----------
        k_t
            Linear tangential contact stiffness [N/m].
        k_n
            Linear normal contact stiffness [N/m].
        stiffness_scale
            Young's modulus as a multiple of the structure's [-].

        Returns
        -------
        frequencies : np.ndarray
            Structural natural frequencies [Hz], ascending, shape (n_modes,).

        Raises
        ------
        ValueError
            When fewer than ``n_modes`` of the lowest ``n_modes`` + 6 modes are structural.
        """
        m = self.model
        n_check = min(m.n_dof, self.n_modes + 6)
        ds = float(stiffness_scale) - 1.0
        if self._basis is not None:
            V, K0r, xr, er = self._basis
            Kr = K0r + k_t * np.outer(xr, xr) + k_n * np.outer(er, er)
            lam, vr = np.linalg.eigh(Kr + ds * self._stiffness_part()[1] if ds else Kr)
            lam, vec = lam[:n_check], V @ vr[:, :n_check]
        else:
            K = self._k0 + k_t * self._xx + k_n * self._ee + (ds * self._stiffness_part()[0] if ds else 0.0)
            lam, vec = scipy.linalg.eigh(K, m.mass, subset_by_index=[0, n_check - 1])
        p = m.params
        frac = (
            p.block_mass * ((m.block_lateral_vector @ vec) ** 2 + (m.block_axial_vector @ vec) ** 2)
            + p.block_inertia * vec[m.thetas_dof] ** 2
        )
        keep = np.flatnonzero(frac < self.max_block_fraction)[: self.n_modes]
        if len(keep) < self.n_modes:
            raise ValueError(f"fewer than {self.n_modes} structural modes among the lowest {n_check}")
        return np.sqrt(np.clip(lam[keep], 0, None)) / (2 * np.pi)

    def _stiffness_part(self) -> tuple:
        """Return K_E and its Ritz projection (or None), made once.

        K_E is the part of K_0 proportional to Young's modulus (bending and axial stiffness; not the clamp, the string
        or gravity), so that a structure with E x s has K_0 + (s - 1) K_E. Made once, when a scale is first asked for
        (the gap model's contact refits never ask).
        """
        if self._ke is None:
            p = self.model.params
            ke = assemble(p.replace(youngs_modulus=2.0 * p.youngs_modulus)).stiffness_without_contact - self._k0
            self._ke = (ke, None if self._basis is None else self._basis[0].T @ ke @ self._basis[0])
        return self._ke


def _m_orthonormal_complement(phi: np.ndarray, shapes: np.ndarray, mass: np.ndarray, rtol: float = 1e-12) -> np.ndarray:
    """Return the part of ``shapes`` (columns) outside the span of the M-orthonormal columns ``phi``, M-orthonormal.

    Gram-Schmidt in the mass metric, each projection done twice; a shape within ``rtol`` of that span (in M-norm) adds
    nothing and is left out. (The contact's static shapes lie within 4e-8 (eta) and 1e-5 (xi) of the lowest 20 modes'
    span on the paper's structure: made M-orthonormal by a Cholesky factor of V^T M V, the eta shape's column made that
    matrix numerically singular on some structures (transducer masses 7 % heavy), and the map fell back to the full
    eigenproblem at every call, eight times the cost.)
    """
    basis = phi
    out = []
    for v in shapes.T:
        size = np.sqrt(v @ mass @ v)
        for _ in range(2):
            v = v - basis @ (basis.T @ (mass @ v))
        norm = np.sqrt(v @ mass @ v)
        if not size > 0 or norm <= rtol * size:
            continue
        v = v / norm
        out.append(v)
        basis = np.column_stack([basis, v])
    return np.column_stack(out) if out else np.zeros((phi.shape[0], 0))
