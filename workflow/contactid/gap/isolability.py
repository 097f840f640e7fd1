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
    """A candidate's signature: its held-out residuals ``after`` less the model's ``before`` ({case: residual}), over
    ``cases``, as one real vector."""
    return np.concatenate([_real(np.asarray(after[c]) - np.asarray(before[c])) for c in cases])


def _without(v: np.ndarray, basis: np.ndarray | None) -> np.ndarray:
    return v if basis is None else v - basis @ (basis.T @ v)


def isolability(signatures: Mapping[str, np.ndarray], form: Sequence[str], limit: float = ISOLABLE_COSINE) -> dict:
    """{"pairs": [{candidates: [a, b], cosine}], "limit", "form_removed"}: the pairs of non-form candidates whose
    signatures, with the form candidates' directions projected out, have a cosine above ``limit`` (most alike first).
    Candidates whose signature is zero (refitted to off) or not finite have no direction and are left out."""
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
