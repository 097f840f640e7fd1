"""Run the diagnosis: the gap measured at every level of the chain, localised, explained by the candidate library.

Its shrinkage is given with its uncertainty. Settings (config ``gap``): the harmonics compared, the candidates, the
thresholds of the verdict and the bootstrap. The verdict names the best candidate only when (1) the held-out gap before
is above ``min_gap`` and the records' own scatter, (2) the candidate shrinks the held-out gap by at least
``min_reduction`` with the bootstrap's lower bound above zero, and (3) it beats the runner-up's held-out gap by the
factor ``separation``; otherwise the verdict is "none" and the localisation says where the gap lies.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np

from ..friction_fit import FitSettings
from ..rig.harmonic_balance import HarmonicBalance
from .candidates import LIBRARY
from .evidence import bootstrap_draws, heldout_gap_draws, heldout_gap_of, shrink_views
from .explain import (
    explain,
    model_periodicity,
    updated_model_summary,
    updating_step,
    updating_summary,
    updating_verdict,
)
from .isolability import isolability, signature
from .localise import localise, place_left
from .model import IdentifiedModel
from .ranking import rank_candidates
from .records import RecordHarmonics
from .refit import baseline, gap_residual
from .settings import GapSettings
from .story import tell
from .story_decisions import resolution
from .verdict import at_floor, gap_shares, retried
from .workers import start_candidates

if TYPE_CHECKING:
    from ..updating_result import UpdatingResult
    from .calibration import Calibration
    from .simulation import SimResult

log = logging.getLogger(__name__)


# ------------------------------------------------------------------------------------------
# ranking and verdict
# ------------------------------------------------------------------------------------------


@dataclass
class Diagnosis:
    """Outcome of the gap diagnosis.

    The verdict and its reason sentence, the candidates' ranking, where the gap lies, the calibration and held-out
    cases, the explanation's steps with the gap they leave, the decisions' trace, the resolution, the shrinkage, the
    updated model, and the arrays and simulations the report plots.

    Attributes
    ----------
    verdict
        The verdict: the effect named, or "none".
    reason
        The verdict's reason, a sentence.
    ranking
        The candidates' ranking rows (``ranking.rank_candidates``), best score first.
    where
        Where the gap lies (``localise.localise``'s summary: place, place_reason, stage gaps, ...), with the held-out
        gap before, its bootstrap interval and the records' scatter (held-out gaps, relative to the records' harmonics).
    calibration_case
        The load case the candidates are refitted on.
    heldout_cases
        The load cases held out (scored).
    arrays
        The localisation's arrays for gap.nc (gap by sensor, harmonic, part of the cycle, ...).
    sims
        {"base" or candidate: {case: simulation}} of the base model and of each candidate.
    shrink
        The held-out gap before and after the winner and the runner-up by case, harmonic and sensor (``shrink_views``).
    explanation
        The explanation's steps, each with the held-out gap before and after it and its share.
    remaining_gap
        What the explanation leaves: held-out gap, share, whether at the floor, and where it lies.
    trace
        The decisions' trace (``story.tell``).
    resolution
        What the records can attribute (``story_decisions.resolution``), with the candidates' isolability.
    updated_model
        The model with the explained effects (``explain.updated_model_summary``).
    """

    verdict: str
    reason: str
    ranking: list
    where: dict
    calibration_case: str
    heldout_cases: list
    arrays: dict = field(default_factory=dict)
    sims: dict = field(default_factory=dict)
    shrink: dict = field(default_factory=dict)
    explanation: list = field(default_factory=list)
    remaining_gap: dict = field(default_factory=dict)
    trace: list = field(default_factory=list)
    resolution: dict = field(default_factory=dict)
    updated_model: dict = field(default_factory=dict)

    def summary(self) -> dict:
        """Return the diagnosis as diagnosis.json holds it.

        Returns
        -------
        summary : dict
            Every field but the arrays, the simulations and the updated model.
        """
        return {
            "verdict": self.verdict,
            "reason": self.reason,
            "resolution": self.resolution,
            "trace": self.trace,
            "ranking": self.ranking,
            "where": self.where,
            "explanation": self.explanation,
            "remaining_gap": self.remaining_gap,
            "shrink": self.shrink,
            "calibration_case": self.calibration_case,
            "heldout_cases": self.heldout_cases,
        }


@dataclass
class _DiagnosisRun:
    """State that every pass of one diagnosis shares.

    The records, the calibration and scored cases, the settings, the baseline simulations and (once drawn) the bootstrap
    resamples of the scored cases' records.

    Attributes
    ----------
    records
        {load case: its record's harmonics}.
    calibration_case
        The load case the candidates are refitted on.
    score_cases
        The load cases scored: the held-out ones (the calibration case where none is held out).
    settings
        The diagnosis's settings.
    fit_settings
        The friction fit's settings.
    workers
        Processes the candidates run in.
    base_sims
        {load case: the base model's simulation}.
    boot
        {scored case: bootstrap resamples of its acceleration harmonics [m/s^2],
        shape (n_bootstrap, n_sensors, n_harmonics)}, empty until drawn.
    channel_delays
        The random test's per-channel delays [s], shape (n_sensors,), where known.
    channel_gains
        The random test's channel gains relative to one another [-], shape (n_sensors,), where known.
    """

    records: Mapping[str, RecordHarmonics]
    calibration_case: str
    score_cases: list
    settings: GapSettings
    fit_settings: FitSettings
    workers: int
    base_sims: dict
    boot: dict = field(default_factory=dict)
    channel_delays: np.ndarray | None = None  # the random test's per-channel delays (s), where known
    channel_gains: np.ndarray | None = None  # the random test's channel gains relative to one another, where known

    @property
    def H(self) -> int:
        return self.settings.n_harmonics

    def candidates(
        self, names: Sequence[str], model: IdentifiedModel, base_sims: dict, **extra: Any
    ) -> Callable[[], dict]:
        """Start the candidates ``names``, calibrated on the calibration case and predicting the scored cases.

        They run in ``workers`` processes (``start_candidates``; call the result to collect them).

        Parameters
        ----------
        names
            The candidates' names (keys of the library).
        model
            The model the candidates are added to.
        base_sims
            {load case: simulation} each candidate's simulations start from.
        **extra
            Further keywords of ``start_candidates`` (base_steps, joint, alone, held_theta).

        Returns
        -------
        collect : Callable[[], dict]
            The function that returns {name: (calibration, simulations by case, residuals by case)}, in library order.
        """
        return start_candidates(
            names,
            self.workers,
            model=model,
            records=self.records,
            calibration_case=self.calibration_case,
            score_cases=self.score_cases,
            base_sims=base_sims,
            fit_settings=self.fit_settings,
            H=self.H,
            max_evaluations=self.settings.max_evaluations,
            channel_delays=self.channel_delays,
            channel_gains=self.channel_gains,
            numerics=self.settings.numerics,
            **extra,
        )

    def draw_bootstrap(self) -> None:
        """Draw the bootstrap over record blocks: the simulations stay fixed, the records are resampled."""
        self.boot = bootstrap_draws(self.records, self.score_cases, self.settings)

    def heldout_gap(self, sims_by_case: Mapping[str, SimResult], boot_index: int | None = None) -> float:
        """Return the held-out gap of these simulations (``heldout_gap_of``), on the records or on one bootstrap draw.

        Parameters
        ----------
        sims_by_case
            {scored case: simulation}.
        boot_index
            Index of the bootstrap draw to score on; None: the records themselves.

        Returns
        -------
        gap : float
            The held-out gap, relative to the records' harmonics [-].
        """
        return heldout_gap_of(
            self.records,
            self.score_cases,
            self.H,
            sims_by_case,
            None if boot_index is None else {c: self.boot[c][boot_index] for c in self.score_cases},
        )

    def heldout_gaps(self, sims_by_case: Mapping[str, SimResult]) -> tuple[float, np.ndarray]:
        """Return the held-out gap and its bootstrap draws.

        Parameters
        ----------
        sims_by_case
            {scored case: simulation}.

        Returns
        -------
        gap : float
            The held-out gap on the records [-].
        draws : np.ndarray
            The held-out gap on each bootstrap draw [-], shape (n_bootstrap,).
        """
        draws = heldout_gap_draws(self.records, self.score_cases, self.H, sims_by_case, self.boot)
        return self.heldout_gap(sims_by_case), draws

    def next_pass(self, results: dict) -> Callable[[Sequence[str], Calibration], dict]:
        """Return the explanation's next pass.

        The remaining candidates are refitted jointly with the steps so far, started from the last step's simulations
        (``explain``).

        Parameters
        ----------
        results
            {candidate: (calibration, simulations by case, residuals by case)} of the first pass.

        Returns
        -------
        run : Callable[[Sequence[str], Calibration], dict]
            The pass: given the remaining candidates and the last step's calibration, their results as ``results``.
        """

        def run(remaining, cal):
            starts = {
                self.calibration_case: cal.simulation
                if cal.simulation is not None
                else self.base_sims[self.calibration_case],
                **{c: s for c, s in results[cal.candidate][1].items() if s is not None},
            }
            return self.candidates(
                remaining,
                cal.model,
                starts,
                base_steps=cal.steps,
                joint=self.settings.joint_refit,
                alone={n: r[0].theta for n, r in results.items()},
            )()

        return run


def _remaining_gap(left, left_share, where, last, run: _DiagnosisRun, linear, structures) -> dict:
    """Return diagnosis.json's ``remaining``: the held-out gap the explanation leaves.

    With its share, whether it is at the floor, and where it lies (localised again with the explanation's effects in,
    where it is above the floor).
    """
    settings = run.settings
    remaining = {
        "heldout_gap": left,
        "share": left_share,
        "at_floor": at_floor(left, settings),
        "floor": settings.min_gap,
        "min_reduction": settings.min_reduction,
        "place": where["place"],
        "place_reason": where["place_reason"],
    }
    if last is not None and not remaining["at_floor"]:
        where_left = place_left(last, run.records, run.calibration_case, run.H, linear, structures, settings)
        if where_left is not None:
            remaining["place"] = where_left["place"]
            remaining["place_reason"] = where_left["place_reason"]
    return remaining


def diagnose(
    model: IdentifiedModel,
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    settings: GapSettings,
    fit_settings: FitSettings,
    linear: dict | None = None,
    workers: int = 1,
    identified: IdentifiedModel | None = None,
    updating: UpdatingResult | None = None,
    channel_delays: np.ndarray | Sequence[float] | None = None,
) -> Diagnosis:
    """Run the whole diagnosis on the load cases' records.

    ``calibration_case`` is used for the refits, the others are held out; the candidates run in ``workers`` processes
    (see ``start_candidates``). With ``identified`` (the chain's own model when ``model`` is its update) the explanation
    starts with the update's step. The channels' gains relative to one another, as the random test's residues show them
    (``updating.channel_gains``), are what the channel-gain candidate applies; without them it adds nothing.

    Parameters
    ----------
    model
        The model to diagnose: the chain's identified model, or its update (``gap.base_model.updated_model``).
    records
        {load case: its dual-sine record's harmonics}.
    calibration_case
        The load case the candidates are refitted on.
    settings
        The diagnosis's settings (config ``gap``).
    fit_settings
        The friction fit's settings, for the candidates' refits of the law.
    linear
        The linear stage's gaps (``localise.linear_stage``: the random test's FRF against the model), added to the stage
        gaps; None: left out.
    workers
        Processes the candidates run in.
    identified
        The chain's own model when ``model`` is its update; None otherwise.
    updating
        The model updating's result (``updating.update_structure``) when ``model`` is its update: its step, its
        posterior structures for the localisation and its channel gains; None: no updating.
    channel_delays
        Each accelerometer channel's delay on the force as the random test shows it (``random_test_delays``) [s],
        shape (n_sensors,), held in common by the channel-delay candidate's refit; None: that refit searches every
        channel's delay from zero.

    Returns
    -------
    diagnosis : Diagnosis
        The verdict, ranking, localisation, explanation and what the report plots.

    Raises
    ------
    ValueError
        When ``calibration_case`` is not among the records' load cases.
    """
    H = settings.n_harmonics
    if calibration_case not in records:
        raise ValueError(f"gap: the calibration case {calibration_case!r} is not among the load cases {list(records)}")
    # a diagnosis starts from no Newton history: a second diagnosis in the same process (a notebook, the benchmark
    # scripts) otherwise started its harmonic balance from the first one's last Jacobian, and its polished
    # searches ended elsewhere (held-out gaps 1.6 % apart with gap.polish_searches on benchmarks/gap_diagnosis.py's
    # viscous data)
    HarmonicBalance.forget()
    held = [c for c in records if c != calibration_case]
    base_sims = {c: baseline(model, records[c], H, settings.numerics)[1] for c in records}
    run = _DiagnosisRun(
        records,
        calibration_case,
        held or [calibration_case],
        settings,
        fit_settings,
        workers,
        base_sims,
        channel_delays=None if channel_delays is None else np.asarray(channel_delays, dtype=float),
        channel_gains=np.asarray(updating.channel_gains, dtype=float) if updating and updating.channel_gains else None,
    )
    # candidates: calibrate, predict the held-out cases (forked before the localisation runs numba's
    # parallel friction kernel in this process)
    library = list(settings.candidates or tuple(LIBRARY))
    # the form candidates (the base model's damping) are the reference of what model-form differences leave, tried
    # whether or not the library in use lists them; named as an effect only where it does (story.tell)
    form = [n for n, c in LIBRARY.items() if c.form]
    names = library + [n for n in form if n not in library]
    candidate_results = run.candidates(names, model, base_sims)
    structures = tuple(updating.posterior_structures()) if updating is not None else ()
    where, arrays = localise(
        model,
        dict(records),
        base_sims,
        H,
        linear,
        eta_limit=settings.eta_observability_limit,
        structures=structures,
        thresholds=settings.place,
        memo=settings.numerics.memo,
    )
    results = candidate_results()
    run.draw_bootstrap()
    before, before_b = run.heldout_gaps(base_sims)
    n_data = 2 * sum(gap_residual(base_sims[c], records[c], H).size for c in run.score_cases)
    rows, boots = rank_candidates(
        results,
        run.heldout_gap,
        settings.n_bootstrap,
        before,
        before_b,
        n_data,
        records,
        calibration_case,
        where,
        settings.place.aperiodic_limit,
        memo=settings.numerics.memo,
    )
    scatter = float(np.std(before_b))
    shrink = {
        label: {
            "effect": r["effect"],
            **shrink_views(records, run.score_cases, base_sims, results[r["effect"]][1], run.boot, H),
        }
        for label, r in zip(("winner", "runner_up"), rows[:2])
    }
    where["heldout_gap_before"] = before
    where["heldout_gap_before_interval"] = [float(np.percentile(before_b, 2.5)), float(np.percentile(before_b, 97.5))]
    where["record_scatter"] = scatter
    if run.channel_delays is not None:  # what the channel-delay refit holds in common (audit)
        sensors = list(getattr(records[calibration_case], "sensors", range(len(run.channel_delays))))
        where["random_test_channel_delays_s"] = {str(k): float(t) for k, t in zip(sensors, run.channel_delays)}
    later = retried({n: r[0].theta for n, r in results.items()}, LIBRARY, settings)

    def delay_seeds(remaining: Sequence[str]) -> dict:
        """Return the per-channel delay candidates among ``remaining`` held at the random test's channel delays.

        For each per-channel delay candidate among ``remaining``, held at the random test's channel delays where those
        are resolved (``DELAY_SEED_MIN``): ``explain``'s further first halves of a pair.

        Parameters
        ----------
        remaining
            The candidates the explanation has not added yet.

        Returns
        -------
        seeds : dict
            {candidate: (its result, the next pass on top of it)}; empty where the delays are not resolved.
        """
        d = run.channel_delays
        if d is None or not np.all(np.isfinite(d)) or np.max(np.abs(d)) < DELAY_SEED_MIN:
            return {}
        out = {}
        for name in remaining:
            cand = LIBRARY[name]
            if not (cand.per_channel and cand.augmentation(np.ones(d.size)).delays):
                continue
            seed = run.candidates([name], model, base_sims, held_theta=d)()[name]
            others = [n for n in remaining if n != name]
            out[name] = (seed, run.next_pass({**results, name: seed})(others, seed[0]))
        return out

    steps, left, last = explain(
        results,
        names,
        before,
        scatter,
        settings,
        run.heldout_gap,
        run.next_pass(results),
        later,
        lambda cal, sims: model_periodicity(cal, sims, records, calibration_case, settings.place.aperiodic_limit),
        delay_seeds,
    )
    first_before = before
    if updating is not None:
        where["model_updating"] = updating_summary(updating, model)
    if identified is not None and updating is not None and updating.accepted:
        first_before = run.heldout_gap(
            {c: baseline(identified, records[c], H, settings.numerics)[1] for c in run.score_cases}
        )
        where["heldout_gap_identified"] = first_before
        steps.insert(0, updating_step(updating, first_before, before))
        log.info("explanation step 0: model updating takes the held-out gap from %.4g to %.4g", first_before, before)
    shares, _ = gap_shares(first_before, [s["heldout_gap_after"] for s in steps])
    for s, share in zip(steps, shares):
        s["share"] = share
    update_effect = None
    if steps and steps[0]["effect"] == "model_updating":
        update_effect = updating_verdict(updating, library, first_before, before, shares, scatter, settings)
    story = tell(
        steps,
        rows,
        before=before,
        scatter=scatter,
        place=where["place"],
        settings=settings,
        form=form,
        model_form=[n for n in form if n not in library],
        n_held=len(held),
        update_effect=update_effect,
    )
    verdict, reason, steps = story.verdict, story.reason, story.explanation
    attributable = resolution(
        before,
        {r["effect"]: r["heldout_gap_after"] for r in rows if r["effect"] in form},
        scatter,
        settings,
        held=bool(held),
    )
    base_res = {c: gap_residual(base_sims[c], records[c], H) for c in run.score_cases}
    attributable["isolability"] = isolability(
        {
            n: signature(base_res, r[2], run.score_cases)
            for n, r in results.items()
            if all(c in r[2] for c in run.score_cases)
        },
        form,
    )
    if not held:
        log.warning("gap diagnosis: %s", reason)
    fits = [s.pop("_fit") for s in steps if "_fit" in s]
    last = fits[-1] if fits else None
    left = steps[-1]["heldout_gap_after"] if steps else before
    left_share = (left / steps[0]["heldout_gap_before"]) ** 2 if steps else 1.0
    remaining = _remaining_gap(left, left_share, where, last, run, linear, structures)
    sims = {"base": base_sims, **{n: r[1] for n, r in results.items()}}
    return Diagnosis(
        verdict,
        reason,
        rows,
        where,
        calibration_case,
        held,
        arrays,
        sims,
        shrink,
        steps,
        remaining,
        trace=story.trace,
        resolution=attributable,
        updated_model=updated_model_summary(identified or model, model, last, steps, left),
    )


# s: the random test's channel delays seed a pair (``diagnose``'s delay_seeds) only where one is at least this large;
# they come out within about 0.9 us of the truth on a structure like the model's (0.91 us on the default data, which
# has no skew), and a seed at that level is the random test's own scatter
DELAY_SEED_MIN = 2.0e-6
