"""Rank the gap diagnosis's candidates.

Each candidate's row: its held-out gap and bootstrap interval against the model's, the score, its refitted parameters
and friction law, whether it acts where the localisation puts the gap and settles where the records do; the rows sorted
by score.
"""

from __future__ import annotations

from typing import Callable, Mapping

import numpy as np

from .candidates import LIBRARY
from .explain import model_periodicity, parameter_values
from .place import acts_where
from .records import RecordHarmonics
from .refit import gap_value, identified_forces


def _ranking_row(
    name: str,
    cal,
    res: Mapping,
    after: float,
    after_b,
    before: float,
    before_b,
    n_data: int,
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    where: Mapping,
    memo: bool = True,
) -> dict:
    """Return a candidate's row of the ranking.

    Its held-out gap (``after``, its bootstrap ``after_b``) against the model's (``before``, ``before_b``), the score (n
    ln(gap^2 ratio) + 2 k over ``n_data`` residual entries), its refitted parameters and friction law, the
    structure/sensor misfit it leaves on the calibration record, and whether it acts where the localisation puts the gap
    (``memo``: the inverse identification memoised, ``Numerics.memo``).
    """
    k = LIBRARY[name].n_parameters(len(records[calibration_case].sensors))
    # does the candidate make the structure and sensor model consistent with the calibration record?
    res_after = float(
        np.sqrt(
            np.mean(
                identified_forces(cal.model, cal.augmentation, records[calibration_case], memo=memo).residual[[0, 2]]
                ** 2
            )
        )
    )
    acts_on = LIBRARY[name].acts_on
    score = n_data * np.log(after**2 / before**2) + 2 * k if np.isfinite(after) else np.inf
    red_b = 1 - after_b / before_b
    return {
        "effect": name,
        "heldout_gap_before": before,
        "heldout_gap_after": after,
        "score": float(score),
        "reduction": 1 - after / before if np.isfinite(after) else -np.inf,
        "reduction_interval": [float(np.percentile(red_b, 2.5)), float(np.percentile(red_b, 97.5))],
        "heldout_gap_after_interval": [float(np.percentile(after_b, 2.5)), float(np.percentile(after_b, 97.5))],
        "n_parameters": k,
        "parameters": parameter_values(name, cal),
        "calibration_gap": cal.gap,
        "friction": [float(x) for x in cal.friction],
        "heldout_gap_after_by_case": {c: gap_value(r) for c, r in res.items()},
        "identification_residual_after": res_after,
        "identification_noise": where["identification_noise"][calibration_case],
        "acts_on": acts_on,
        # a winner must act where the localisation puts the gap; the structure/sensor misfit left by the candidate
        # (identification_residual_after, against the noise level) is reported beside it
        "consistent": bool(acts_where(acts_on, where["place"])),
        "evaluations": cal.evaluations,
    }


def rank_candidates(
    results: Mapping[str, tuple],
    heldout_gap: Callable[..., float],
    n_bootstrap: int,
    before: float,
    before_b: np.ndarray,
    n_data: int,
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    where: Mapping,
    aperiodic_limit: float = 0.1,
    memo: bool = True,
) -> tuple[list, dict]:
    """Return the candidates' ranking rows, sorted by score, and each candidate's bootstrap held-out gaps.

    Scores equal to 3 decimals are a tie (the same model solved from other starts): library order. Each row also says
    where the candidate's model settles unlike the records (``model_periodicity`` with ``aperiodic_limit``). A candidate
    whose held-out prediction diverged explains nothing: its gaps are infinite.

    Parameters
    ----------
    results
        {candidate: (calibration, simulations by case, residuals by case)} (``start_candidates``' results).
    heldout_gap
        The held-out gap of simulations by case, called as heldout_gap(sims) on the records and heldout_gap(sims, b) on
        bootstrap draw b (``_DiagnosisRun.heldout_gap``), returning the relative gap [-].
    n_bootstrap
        Number of bootstrap draws.
    before
        The model's held-out gap before any candidate [-].
    before_b
        The model's held-out gap on each bootstrap draw [-], shape (n_bootstrap,).
    n_data
        Number of residual entries the score counts (real and imaginary parts of the scored harmonics).
    records
        {load case: its record's harmonics}.
    calibration_case
        The load case the candidates are refitted on.
    where
        The localisation's summary (``localise.localise``); read: place, identification_noise.
    aperiodic_limit
        Share of a response not periodic at the drive above which it does not settle (``gap.place.aperiodic_limit``)
        [-].
    memo
        Whether the inverse identifications are memoised (``Numerics.memo``).

    Returns
    -------
    rows : list
        The ranking rows (dicts: effect, held-out gaps before and after with intervals, score, reduction, parameters,
        friction, consistent, periodicity, ...), best score first.
    boots : dict
        {candidate: its held-out gap on each bootstrap draw [-], shape (n_bootstrap,)}.
    """
    rows, boots = [], {}
    for name, (cal, sims, res) in results.items():
        after = heldout_gap(sims)
        after_b = np.array([heldout_gap(sims, b) for b in range(n_bootstrap)])
        if not np.isfinite(after):  # a held-out prediction diverged: the candidate explains nothing
            after, after_b = np.inf, np.full(n_bootstrap, np.inf)
        boots[name] = after_b
        rows.append(
            _ranking_row(
                name, cal, res, after, after_b, before, before_b, n_data, records, calibration_case, where, memo
            )
        )
        rows[-1].update(model_periodicity(cal, sims, records, calibration_case, aperiodic_limit))
    rows.sort(key=lambda r: round(r["score"], 3) if np.isfinite(r["score"]) else np.inf)
    return rows, boots
