"""The candidates' refits and the pool of forked worker processes that runs them at once.

Each candidate is calibrated on the calibration case (on top of the explanation's earlier steps) and predicts the
scored cases.
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..friction_fit import FitSettings
from ..rig.harmonic_balance import HarmonicBalance
from .calibration import calibrate, held
from .candidates import LIBRARY, joint_candidate, merged_augmentation
from .model import IdentifiedModel
from .numerics import DEFAULT, Numerics
from .records import RecordHarmonics
from .refit import evaluate, gap_residual, gap_value

log = logging.getLogger(__name__)


def _candidate(
    name: str,
    model: IdentifiedModel,
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    score_cases: list,
    base_sims: dict,
    fit_settings: FitSettings,
    H: int,
    max_evaluations: int,
    base_steps: tuple = (),
    joint: bool = True,
    alone: dict | None = None,
    channel_delays=None,
    channel_gains=None,
    held_theta=None,
    numerics: Numerics = DEFAULT,
):
    """Refit one candidate added to the explanation's earlier steps ``base_steps`` ((name, theta), ...).

    Calibrated on the calibration case (with ``joint``, together with the earlier steps' parameters,
    ``joint_candidate``; otherwise with them held), predicted on the scored cases (each simulation warm-started from the
    baseline's). ``alone``: {name: theta} of the first pass (each candidate alone); a joint refit also starts between
    the earlier steps' optimum and this candidate's own (two effects that can stand in for each other, viscous friction
    and a normal dashpot, leave a ridge between the one-effect optimum and the truth). ``channel_delays``: the random
    test's per-channel delays and ``channel_gains`` its channels' relative gains (``calibration.calibrate``).
    ``held_theta``: the candidate at this theta, not searched (``calibration.held``; the earlier steps held).
    ``numerics``: how the steady states are found and the searches run (``numerics.Numerics``, the diagnosis's
    ``GapSettings.numerics``; an argument of the task, so that a worker process sees it too). Returns (calibration,
    sims, residuals) by case.
    """
    rec = records[calibration_case]
    # per-channel effects (channel delays) trade off with no contact effect and would add a dimension per channel:
    # they are held, and a per-channel candidate is refitted on the earlier steps held
    free = [n for n, _ in base_steps if not LIBRARY[n].per_channel]
    if held_theta is not None:
        base = merged_augmentation((LIBRARY[n], th) for n, th in base_steps)
        cal = held(
            model,
            LIBRARY[name],
            rec,
            fit_settings,
            H,
            held_theta,
            start=base_sims[calibration_case],
            base=base,
            numerics=numerics,
        )
        cal = dataclasses.replace(cal, steps=tuple(base_steps) + ((name, cal.theta),))
    elif free and joint and not LIBRARY[name].per_channel:
        base = merged_augmentation((LIBRARY[n], th) for n, th in base_steps if n not in free)
        cand, split = joint_candidate(
            LIBRARY[name], [(LIBRARY[n], th) for n, th in base_steps if n in free], rec.acceleration.shape[0]
        )
        mixes = ()
        if alone and name in alone:
            first = np.array([p.start for p in cand.parameters])  # the earlier optimum, this effect off
            own = first.copy()  # this effect at its one-effect optimum, the earlier ones off
            n_new = len(np.atleast_1d(alone[name]))
            own[:n_new] = np.atleast_1d(alone[name])
            own[n_new:] = [p.off for p in cand.parameters[n_new:]]
            mixes = tuple((1 - t) * first + t * own for t in (1 / 3, 2 / 3))
        cal = calibrate(
            model,
            cand,
            rec,
            fit_settings,
            H,
            max_evaluations,
            start=base_sims[calibration_case],
            starts=mixes,
            base=base,
            numerics=numerics,
        )
        own_theta, *refitted = split(cal.theta)
        refitted = dict(zip(free, refitted))
        cal = dataclasses.replace(
            cal, theta=own_theta, steps=tuple((n, refitted.get(n, th)) for n, th in base_steps) + ((name, own_theta),)
        )
    else:
        base = merged_augmentation((LIBRARY[n], th) for n, th in base_steps)
        cal = calibrate(
            model,
            LIBRARY[name],
            rec,
            fit_settings,
            H,
            max_evaluations,
            start=base_sims[calibration_case],
            base=base,
            channel_delays=channel_delays,
            channel_gains=channel_gains,
            numerics=numerics,
        )
        cal = dataclasses.replace(cal, steps=tuple(base_steps) + ((name, cal.theta),))
    sims = {calibration_case: None}
    res = {}
    for c in score_cases:
        _, _, sim, _ = evaluate(
            cal.model, cal.augmentation, records[c], None, H, refit=False, start=base_sims[c], numerics=numerics
        )
        sims[c] = sim
        res[c] = gap_residual(sim, records[c], H)
    log.info(
        "candidate %s: theta [%s], calibration gap %.4g, held-out gap %s",
        name,
        ", ".join(f"{t:.4g}" for t in np.ravel(cal.theta)),
        cal.gap,
        ", ".join(f"{c} {gap_value(r):.4g}" for c, r in res.items()),
    )
    return cal, sims, res


def _candidate_task(task):
    """Run ``_candidate(name, **common)`` for a task (name, common).

    ``common["numerics"]``: the diagnosis's numerical settings, handed to the process that runs the candidate with the
    task. Each candidate starts without Newton history (``HarmonicBalance.forget``): which worker runs which candidate
    after which depends on timing, and a candidate that started from another's last Jacobian ended elsewhere where its
    calibration gap is flat (the default data's transducer-mass refit, mass error 0.0075 in one run and 0.0104 in the
    next).
    """
    name, common = task
    HarmonicBalance.forget()
    return _candidate(name, **common)


def fork_safe() -> bool:
    """Return whether worker processes may be forked here.

    Not after numba's parallel threads have started (its default threading layer, workqueue, is not fork-safe; TBB
    is).

    Returns
    -------
    bool
        True where forking is safe: numba's parallel threads have not started, or they run on TBB.
    """
    import numba
    from numba.np.ufunc import parallel as _parallel

    return not getattr(_parallel, "_is_initialized", True) or numba.threading_layer() == "tbb"


_POOLS: dict = {}  # workers -> a pool forked while that was safe, kept for the process's later diagnoses


def _pool(workers: int):
    """Return a pool of ``workers`` forked processes, or None if it cannot be made safely.

    Made while forking is safe (``fork_safe``) and then reused.
    """
    if workers not in _POOLS:
        if not fork_safe():
            return None
        import atexit
        import multiprocessing

        pool = multiprocessing.get_context("fork").Pool(workers)
        atexit.register(pool.terminate)
        _POOLS[workers] = pool
    return _POOLS[workers]


def prepare_workers(workers: int) -> bool:
    """Fork the candidates' worker processes now, while forking is safe.

    Before anything in this process runs numba's parallel friction kernel, e.g. the friction fit after model updating.

    Parameters
    ----------
    workers
        Number of worker processes (1 or fewer: none).

    Returns
    -------
    bool
        True if the worker processes exist.
    """
    return workers > 1 and _pool(workers) is not None


def start_candidates(names: Sequence[str], workers: int, **common: Any) -> Callable[[], dict[str, tuple]]:
    """Start the candidates' refits and return a function that collects them.

    With ``workers`` > 1 they run at once in forked worker processes while this process goes on (the results equal the
    serial ones to the last digit: each candidate starts without Newton history, ``_candidate_task``); serially, when
    the function is called. A pool can only be forked before numba's parallel threads start in this process (in a rule
    script: before the localisation runs the friction kernel); later calls reuse it.

    Parameters
    ----------
    names
        The library's names of the candidates to refit, in library order.
    workers
        Number of worker processes (at most one per candidate; 1: serially).
    **common
        The keyword arguments of ``_candidate`` every candidate shares (model, records, calibration_case,
        score_cases, base_sims, fit_settings, H, max_evaluations, base_steps, ...).

    Returns
    -------
    collect : Callable[[], dict[str, tuple]]
        Called without arguments, gives {name: (calibration, sims, residuals)} in library order (waiting for the
        workers).
    """
    workers = max(1, min(int(workers), len(names)))
    pool = _pool(workers) if workers > 1 else None
    if workers > 1 and pool is None:
        log.info(
            "gap candidates: numba's parallel threads already run in this process; one process instead of %d", workers
        )
    if pool is None:
        return lambda: {name: _candidate_task((name, common)) for name in names}
    pending = pool.map_async(_candidate_task, [(name, common) for name in names], chunksize=1)
    return lambda: dict(zip(names, pending.get()))
