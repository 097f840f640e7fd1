"""Which candidates the records cannot tell apart: an isolability table from the candidates' signatures.

A candidate's signature is the change its refit makes to the held-out residual (the sensors' harmonics of every
held-out case, scaled as the held-out gap is: ``refit.gap_residual``). Two candidates whose signatures point the same
way, once what the form candidates (the base model's damping) can absorb is projected out, change the held-out
records alike: no refit on these records tells one from the other, whatever their held-out gaps. The cosine of the two
signatures (real inner product of the complex residual changes) measures it; ``ISOLABLE_COSINE`` is where a pair is
called not isolable.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

# a pair whose signatures, the form candidates' directions removed, have a cosine above this is not isolable: 0.9 leaves
# a fifth of either's change (sqrt(1 - 0.9^2) = 0.44 of its norm) outside the other's direction
ISOLABLE_COSINE = 0.9


def _real(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v)
    return np.concatenate([v.real.ravel(), v.imag.ravel()]) if np.iscomplexobj(v) else v.ravel().astype(float)


def signature(before: Mapping[str, np.ndarray], after: Mapping[str, np.ndarray], cases: Sequence[str]) -> np.ndarray:
    """Return a candidate's signature: its held-out residuals less the model's, as one real vector.

    The changes ``after - before`` of the residuals over ``cases``, concatenated.

    Parameters
    ----------
    before
        The model's held-out residuals by case ({case: residual}, ``refit.gap_residual``: complex, scaled by the
        record's acceleration harmonics' norm) [-], each of shape (n_residual,) with n_residual = 2 n_sensors
        n_harmonics.
    after
        The candidate's refitted held-out residuals by case, as ``before`` [-], each of shape (n_residual,).
    cases
        The held-out cases, in the order their changes are concatenated.

    Returns
    -------
    signature : np.ndarray
        The residual changes ``after - before`` of every case, real parts then imaginary parts of each case's change
        (real residuals as they are) [-], shape (2 n_residual n_cases,).
    """
    return np.concatenate([_real(np.asarray(after[c]) - np.asarray(before[c])) for c in cases])


def _without(v: np.ndarray, basis: np.ndarray | None) -> np.ndarray:
    return v if basis is None else v - basis @ (basis.T @ v)


def isolability(signatures: Mapping[str, np.ndarray], form: Sequence[str], limit: float = ISOLABLE_COSINE) -> dict:
    """Return the pairs of non-form candidates that the records cannot tell apart.

    These are the pairs whose signatures, with the form candidates' directions projected out, have a cosine above
    ``limit`` (most alike first). Candidates whose signature is zero (refitted to off) or not finite have no direction
    and are left out.

    Parameters
    ----------
    signatures
        Each candidate's signature by name ({candidate: ``signature``}) [-], each of shape (n_signature,), the same
        for every candidate.
    form
        The form candidates (the base model's damping): their directions are projected out of the others'.
    limit
        Cosine above which a pair is not isolable [-].

    Returns
    -------
    table : dict
        {"pairs": [{"candidates": [a, b], "cosine": cosine}, ...], "limit": ``limit``, "form_removed": the form
        candidates whose directions were projected out}; the cosines [-].
    """
    finite = {k: np.asarray(v, float) for k, v in signatures.items() if np.all(np.isfinite(v)) and np.any(v)}
    forms = [finite[k] for k in form if k in finite]
    basis = np.linalg.qr(np.column_stack(forms))[0] if forms else None
    dirs = {}
    for k, v in finite.items():
        if k in form:
            continue
        w = _without(v, basis)
        n = np.linalg.norm(w)
        if n > 1e-12 * max(np.linalg.norm(v), 1e-300):
            dirs[k] = w / n
    names = list(dirs)
    pairs = []
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            c = float(dirs[a] @ dirs[b])
            if c > limit:
                pairs.append({"candidates": [a, b], "cosine": c})
    pairs.sort(key=lambda p: -p["cosine"])
    return {"pairs": pairs, "limit": float(limit), "form_removed": [k for k in form if k in finite]}
