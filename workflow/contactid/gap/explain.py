"""The additive explanation of the held-out gap, its step 0 (the model update) and the model it arrives at.

The candidates are added one at a time (or in pairs) while each shrinks what is left materially, with each step's
refitted parameters, whether its model opens the contact and settles where the records do; the accepted model update
is the explanation's step 0 (and the verdict it may carry); and the model the explanation arrives at is
results/gap/updated_model.json.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Callable, Collection, Mapping, Sequence

import numpy as np

from ..contact_laws import stiction_shear_stiffness
from ..friction_parameters import PARAMETER_NAMES
from .candidates import LIBRARY
from .model import NONE, IdentifiedModel
from .place import DEFAULT_PLACE
from .verdict import (
    UPDATING_EFFECTS,
    UPDATING_Z,
    at_floor,
    explains_materially,
    explains_most,
    gap_shares,
    indistinguishable,
    moved_factors,
    updating_effect,
)

if TYPE_CHECKING:
    from ..updating_result import UpdatingResult
    from .calibration import Calibration
    from .records import RecordHarmonics
    from .settings import GapSettings
    from .simulation import SimResult

log = logging.getLogger(__name__)


def parameter_values(name: str, cal: Calibration | None = None, theta: np.ndarray | None = None) -> dict:
    """Return a calibrated candidate's refitted parameters by name.

    Parameters
    ----------
    name
        The candidate's name in the library.
    cal
        Its calibration: its ``theta`` is read where ``theta`` is None.
    theta
        The candidate's parameter values, each in its ``Parameter.unit`` [unit of Parameter.unit],
        shape (n_parameters,) (per channel: one per accelerometer channel); None: ``cal.theta``.

    Returns
    -------
    values : dict
        {parameter name: value}, per-channel ones numbered by channel (``delay_0``, ``delay_1``, ...).
    """
    cand = LIBRARY[name]
    theta = np.atleast_1d(cal.theta if theta is None else theta)
    return {
        p.name if not cand.per_channel else f"{p.name}_{i}": float(v)
        for i, (p, v) in enumerate(zip(cand.parameters * len(theta), theta))
    }


def contact_opens(cal: Calibration, sims: Mapping[str, SimResult], open_limit: float) -> bool | None:
    """Judge whether a calibrated candidate's model opens the contact anywhere.

    Open: its N falls to ``open_limit`` x the preload or below over the period, in the calibration case's simulation
    or a scored case's. A normal law that may open (contact_separation) but never does in these simulations acts as
    a stiffer or harder normal law than Eq. 13's spring: model form, not separation (the compound benchmark's
    hardening rigs, docs/gap.md).

    Parameters
    ----------
    cal
        The candidate's calibration (its ``simulation`` and ``model``).
    sims
        The scored cases' simulations, by case.
    open_limit
        The share of the preload at or below which the contact is open [-] (``gap.place.open_limit``).

    Returns
    -------
    opens : bool | None
        Whether it opens; None: no simulation (or no model) to tell.
    """
    runs = [getattr(cal, "simulation", None), *sims.values()]
    grids = [sim.grid["N"] for sim in runs if isinstance(getattr(sim, "grid", None), dict) and "N" in sim.grid]
    if not grids or getattr(cal, "model", None) is None:
        return None
    return any(bool(np.min(N) <= open_limit * cal.model.preload) for N in grids)


def model_periodicity(
    cal: Calibration,
    sims: Mapping[str, SimResult],
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    limit: float,
) -> dict:
    """Judge whether a calibrated candidate's model settles where the records do.

    Per case (the calibration case's simulation ``cal.simulation`` and the scored ones ``sims``), the largest share
    of the model's sensor response that is not periodic (0 for a periodic state or a settled march; a drifting
    record's is left out), and the cases where the model settles and the record does not, or the other way round
    (each judged by ``limit``). A law whose model impacts on a record that settled (or settles on one that did not)
    is wrong in form, whatever its harmonic gap: the harmonics of a response that never repeats are averages.

    Parameters
    ----------
    cal
        The candidate's calibration (its ``simulation``, the calibration case's).
    sims
        The scored cases' simulations, by case.
    records
        The records' harmonics, by case (their ``aperiodic`` shares).
    calibration_case
        The calibration case's name.
    limit
        The share of a response's rms not periodic above which it does not settle [-]
        (``gap.place.aperiodic_limit``).

    Returns
    -------
    periodicity : dict
        ``aperiodic_by_case`` ({case: the model's largest aperiodic share, as a fraction}) and
        ``settles_unlike_records`` (the cases where model and record differ).
    """
    runs = {}
    for c in records:
        sim = getattr(cal, "simulation", None) if c == calibration_case else sims.get(c)
        if sim is None or getattr(sim, "first", None) is not None:  # no simulation, or a drifting record's
            continue
        a = (getattr(sim, "extra", None) or {}).get("aperiodic")
        runs[c] = float(np.max(a)) if a is not None and np.size(a) else 0.0
    unlike = []
    for c, share in runs.items():
        rec = getattr(records[c], "aperiodic", None)
        if rec is not None and np.size(rec) and (share > limit) != (float(np.max(rec)) > limit):
            unlike.append(c)
    return {"aperiodic_by_case": runs, "settles_unlike_records": unlike}


def explain(  # noqa: C901
    first: dict,
    names: list,
    before: float,
    scatter: float,
    settings: GapSettings,
    heldout_gap: Callable[[Mapping[str, SimResult]], float],
    next_pass: Callable[[list, Calibration], dict],
    later: list | None = None,
    periodicity: Callable[[Calibration, Mapping[str, SimResult]], dict] | None = None,
    seeded: Callable[[list], dict] | None = None,
) -> tuple[list, float, tuple | None]:
    """Explain the held-out gap additively: candidates added one at a time, or in pairs, while each shrinks it.

    Add the candidate that leaves the smallest held-out gap (its refit included), then try the remaining candidates on
    top of it (``next_pass(remaining, calibration)`` gives their results), and so on; stop when no candidate shrinks
    what is left materially (``verdict.explains_materially``) or what is left is at the identification's floor
    (``verdict.at_floor``). Where what is left exceeds ``settings.pair_lookahead`` times the floor (0: never) and the
    best candidate shrinks it beyond the records' scatter but not materially, the next pass is tried on top of it: two
    effects that each leave most of the gap may together explain it (a preload drift and a normal dashpot, 36 % and 24 %
    alone); the pair is added when together they shrink it materially and the second shrinks it further beyond the
    scatter. Before any step (and unless the lookahead is 0), ``seeded(remaining)`` ({seed: (its result, the next pass
    on top of it)}, or None) offers more first halves of a pair: an effect measured elsewhere and held there (the random
    test's channel delays), which alone may widen the gap by exposing a second effect it masks (a channel skew of 10-30
    us and a normal dashpot of 400 s/m: the dashpot refitted to zero, the skew searched away from its delays; held at
    them, the dashpot took 2.54 to 0.44 %). Held, it adds no parameter the records fit, so its pair competes with the
    pass's best alone as well: it is added where it leaves less than that best and than the seed alone, beyond the
    scatter, and explains materially. The pair that leaves the least is added.

    Parameters
    ----------
    first
        {name: (calibration, sims, residuals)} of the first pass.
    names
        The candidates' names, in the library's order (ties go to the earlier).
    before
        The held-out gap before any step [-] (a relative residual norm).
    scatter
        The records' scatter of the held-out gap [-] (its bootstrap sd).
    settings
        The diagnosis's settings (``noise_factor``, ``pair_lookahead``, ``min_gap``, the verdict's thresholds,
        ``place.open_limit``).
    heldout_gap
        heldout_gap(sims): the held-out gap [-] of a model's simulations by case.
    next_pass
        next_pass(remaining, calibration): the remaining candidates' results on top of the last step's calibration,
        {name: (calibration, sims, residuals)}.
    later
        The candidates tried after the first pass (``verdict.retried``); None: all.
    periodicity
        periodicity(cal, sims): a step's ``model_periodicity``; None: not reported.
    seeded
        seeded(remaining): {seed: (its result, the next pass on top of it)}, the seeds' pairs; None: no seeds.

    Returns
    -------
    steps : list
        [{effect, parameters, heldout_gap_before, heldout_gap_after, alternatives, share, contact_opens, ...}]:
        share, the part of the held-out gap's power (its square) the step removes (the shares and the remaining
        share sum to 1); alternatives, the candidates of the step's pass that the records cannot tell from its
        effect (``verdict.indistinguishable``), closest first; ``held`` and ``pair_first`` where they apply, the
        periodicity's keys where reported, and ``_fit`` (calibration, sims), not written.
    gap : float
        The held-out gap left [-].
    last : tuple | None
        (calibration, sims) of the last step; None: no step.
    """
    steps, gap, last, results, remaining = [], before, None, first, list(names)
    held_step = None  # a seed's effect added at the values measured elsewhere
    beyond_scatter = settings.noise_factor * scatter

    def finite_gaps(res, names_):
        gaps_ = {n: heldout_gap(res[n][1]) for n in names_}
        return {n: g for n, g in gaps_.items() if np.isfinite(g)}

    while remaining and not at_floor(gap, settings):
        gaps = finite_gaps(results, remaining)
        if not gaps:
            break
        best = min(gaps, key=gaps.get)  # ties: library order
        chosen = [(best, results[best], gaps[best], indistinguishable(gaps, best, settings))]

        def pair_on(first_name, res_first, gap_first, alts_first, results2, held_first=False):
            # (gap, first step, second step, whether the first is held) of the pass ``results2`` on top of a first
            # half, where its best leaves less than the first half alone and than the pass's best, beyond the scatter,
            # and explains materially
            gaps2 = finite_gaps(results2, [n for n in results2 if n != first_name])
            best2 = min(gaps2, key=gaps2.get) if gaps2 else None
            if best2 is None or not (
                gaps2[best2] < min(gaps[best], gap_first) - beyond_scatter
                and explains_materially(gap, gaps2[best2], scatter, settings)
            ):
                return None
            second = (best2, results2[best2], gaps2[best2], indistinguishable(gaps2, best2, settings))
            return gaps2[best2], (first_name, res_first, gap_first, alts_first), second, held_first

        # seeds (before any step): a pair on an effect held where the random test measured it adds no parameter the
        # records fit, so it competes with the pass's best alone as well as with its pair
        seeds = []
        if seeded is not None and not steps and settings.pair_lookahead:
            for seed, (res_seed, res2) in seeded(list(remaining)).items():
                pair = pair_on(seed, res_seed, heldout_gap(res_seed[1]), [], res2, held_first=True)
                if pair is not None:
                    seeds.append(pair)
        pairs = list(seeds)
        if not explains_materially(gap, gaps[best], scatter, settings):
            lookahead = settings.pair_lookahead
            if not (lookahead and gap > lookahead * settings.min_gap):
                break
            # the pass's best as a first half, where it shrinks the gap beyond the scatter
            others = [n for n in remaining if n != best and (later is None or n in later)]
            if others and gaps[best] < gap - beyond_scatter:
                pair = pair_on(best, chosen[0][1], gaps[best], chosen[0][3], next_pass(others, results[best][0]))
                if pair is not None:
                    pairs.insert(0, pair)
            if not pairs:
                break
        if pairs:
            _, first_step, second_step, held_first = min(pairs, key=lambda p: p[0])
            held_step = first_step[0] if held_first else None
            log.info(
                "explanation: %s alone leaves %.4g of %.4g, with %s %.4g: the pair is added",
                first_step[0],
                first_step[2],
                gap,
                second_step[0],
                second_step[2],
            )
            chosen = [first_step, second_step]
        for k, (name, (cal, sims, _), after, alternatives) in enumerate(chosen):
            steps.append(
                {
                    "effect": name,
                    "parameters": parameter_values(name, cal),
                    "heldout_gap_before": gap,
                    "heldout_gap_after": after,
                    "alternatives": alternatives,
                    "contact_opens": contact_opens(cal, sims, getattr(settings, "place", DEFAULT_PLACE).open_limit),
                }
            )
            if name == held_step:  # not refitted on the records: held where the random test measured it
                steps[-1]["held"] = True
            if k == 0 and len(chosen) > 1:  # a pair's first half: judged with its second (story.tell)
                steps[-1]["pair_first"] = True
            if periodicity is not None:
                steps[-1].update(periodicity(cal, sims))
            if len(cal.steps) > 1:  # the earlier steps' parameters as refitted with this one (gap.joint_refit)
                steps[-1]["earlier_refitted"] = {n: parameter_values(n, theta=th) for n, th in cal.steps[:-1]}
            log.info("explanation step %d: %s leaves a held-out gap of %.4g (from %.4g)", len(steps), name, after, gap)
            steps[-1]["_fit"] = (cal, sims)  # for the place of what is left (diagnose), not written
            gap, last = after, (cal, sims)
            remaining.remove(name)
        remaining = [n for n in remaining if later is None or n in later]
        if remaining and not at_floor(gap, settings):
            results = next_pass(remaining, last[0])
    shares, _ = gap_shares(before, [s["heldout_gap_after"] for s in steps])
    for s, share in zip(steps, shares):
        s["share"] = share
    return steps, gap, last


def updating_summary(updating: UpdatingResult, model: IdentifiedModel) -> dict:
    """Return diagnosis.json's model_updating block.

    The update's summary and the friction law the candidates start from (refitted with the updated structure when
    the update is accepted).

    Parameters
    ----------
    updating
        The model update.
    model
        The model the candidates start from (its friction law and preload).

    Returns
    -------
    block : dict
        The update's ``summary()`` with ``friction``: e_f, k_c, e_t, kappa, mu (in their units,
        ``friction_parameters.PARAMETER_UNITS``) and e0_at_preload (N/m).
    """
    e_f, k_c, e_t, kappa, mu = model.friction
    return {
        **updating.summary(),
        "friction": {
            "e_f": e_f,
            "k_c": k_c,
            "e_t": e_t,
            "kappa": kappa,
            "mu": mu,
            "e0_at_preload": float(stiction_shear_stiffness(model.preload, e_f, k_c)),
        },
    }


def updating_step(updating: UpdatingResult, gap_before: float, gap_after: float) -> dict:
    """Return the explanation's step 0 when the model updating was accepted.

    The factors (and the clamp's stiffness in N m/rad where the data bind its compliance, which a test engineer reads
    more easily than the factor) and the held-out gap it took away.

    Parameters
    ----------
    updating
        The accepted model update.
    gap_before
        The identified model's held-out gap [-].
    gap_after
        The updated model's held-out gap [-].

    Returns
    -------
    step : dict
        {effect: "model_updating", parameters (the factors, k_t and k_n in N/m, the clamp's stiffness in N m/rad
        where bound), heldout_gap_before, heldout_gap_after}.
    """
    k_clamp = updating.structure.clamp_rotational_stiffness
    bound = (updating.identifiability.get("clamp_compliance_scale") or {}).get("bound_by_data", False)
    clamp = {"clamp_rotational_stiffness_nm_per_rad": k_clamp} if bound and np.isfinite(k_clamp) else {}
    return {
        "effect": "model_updating",
        "parameters": {**updating.factors, **clamp, "k_t": updating.k_t, "k_n": updating.k_n},
        "heldout_gap_before": gap_before,
        "heldout_gap_after": gap_after,
    }


def updating_verdict(
    updating: UpdatingResult,
    names: Collection[str],
    gap_before: float,
    gap_after: float,
    shares: Sequence[float],
    scatter: float,
    settings: GapSettings,
) -> tuple[str, str] | None:
    """Return the accepted update's verdict and reason where it explains most of the gap as one effect.

    Most of the gap: the largest share, and min_reduction of the whole gap as a candidate's verdict needs
    (``verdict.explains_most``); one effect: of the library in use (``verdict.updating_effect``).

    Parameters
    ----------
    updating
        The accepted model update.
    names
        The library in use: the candidates' names.
    gap_before
        The identified model's held-out gap [-].
    gap_after
        The updated model's held-out gap [-].
    shares
        The explanation's steps' shares of the gap's power, the update's first [-].
    scatter
        The records' scatter of the held-out gap [-].
    settings
        The diagnosis's settings.

    Returns
    -------
    verdict : tuple[str, str] | None
        (the effect's name, the reason); None where the update does not explain most of the gap or amounts to no
        effect of the library.
    """
    if shares[0] != max(shares) or not explains_most(gap_before, gap_after, scatter, settings):
        return None
    by_records = getattr(updating, "accepted_by", "") == "records"
    attribution = (getattr(updating, "records_test", None) or {}).get("attribution")
    effect = updating_effect(updating.factors, updating.identifiability, by_records, attribution)
    if effect is None or effect not in names:
        return None
    if attribution and attribution.get("effect") == effect and by_records:
        f = next(k for k, v in UPDATING_EFFECTS.items() if v == effect)
        g = {k: ("nothing finite" if v is None else f"{v:.3g}") for k, v in attribution["factors"][f].items()}
        why = f"the records tell the factor: {effect} alone leaves {g['alone']}, the update without it {g['without']}"
    elif by_records or not moved_factors(updating.factors, updating.identifiability):
        why = f"the random test's profiles put it on the {effect.replace('_error', '')} factors"
    else:
        why = f"only the {effect.replace('_error', '')} factors moved beyond {UPDATING_Z:g} standard deviations"
    return effect, (
        f"model updating ({', '.join(f'{k} {v:.3g}' for k, v in updating.factors.items())}) takes the "
        f"held-out gap from {gap_before:.3g} to {gap_after:.3g} ({shares[0]:.0%} of its power); {why}"
    )


def _friction_dict(friction, preload: float) -> dict:
    e_f, k_c, e_t, kappa, mu = (float(x) for x in friction)
    return {
        "e_f": e_f,
        "k_c": k_c,
        "e_t": e_t,
        "kappa": kappa,
        "mu": mu,
        "e0_at_preload": float(stiction_shear_stiffness(preload, e_f, k_c)),
    }


def updated_model_summary(
    chain: IdentifiedModel, base: IdentifiedModel, last: tuple | None, steps: list, left: float
) -> dict:
    """Return results/gap/updated_model.json: the model the explanation arrives at.

    The structure and the friction law refitted with the explained effects, beside the chain's own law.

    Parameters
    ----------
    chain
        The chain's identified model (its own law).
    base
        The model diagnosed (updated or the chain's), used where no effect was explained.
    last
        The last effect step's (calibration, sims); None: no effect step.
    steps
        The explanation kept.
    left
        The held-out gap it leaves [-].

    Returns
    -------
    summary : dict
        what, effects, model_updating, friction, friction_chain, structure (stiffnesses in N/m, Young's modulus in
        Pa, lever arm in m, masses in kg, the clamp's stiffness in N m/rad, the extra damping ratio),
        calibration_gap and heldout_gap.
    """
    cal = last[0] if last is not None else None
    model = cal.model if cal is not None else base
    friction = cal.friction if cal is not None else model.friction
    aug = cal.augmentation if cal is not None else NONE
    structure = model.structure_with(aug)
    effects = {n: parameter_values(n, theta=th) for n, th in cal.steps} if cal is not None else {}
    update = next((s for s in steps if s["effect"] == "model_updating"), None)
    return {
        "what": (
            "the identified model with the explanation's effects, the friction law refitted with them on the "
            "calibration case"
            if effects
            else "the identified model" + (" as model updating left it" if update else "") + " (no effect explained)"
        ),
        "effects": effects,
        "model_updating": update["parameters"] if update else None,
        "friction": _friction_dict(friction, model.preload),
        "friction_chain": _friction_dict(chain.friction, chain.preload),
        "structure": {
            "k_t_n_per_m": float(structure.k_t),
            "k_n_n_per_m": float(structure.k_n),
            "youngs_modulus_pa": float(structure.youngs_modulus),
            "tangential_lever_arm_m": float(structure.tangential_lever_arm),
            "sensor_masses_kg": [float(m) for m in structure.sensor_masses],
            "force_transducer_mass_kg": float(structure.force_transducer_mass),
            "clamp_rotational_stiffness_nm_per_rad": float(structure.clamp_rotational_stiffness),
            "extra_damping_ratio": float(aug.extra_damping),
        },
        "calibration_gap": float(cal.gap) if cal is not None else None,
        "heldout_gap": float(left),
    }


def with_damping_at_test_level(
    updated: dict, test_damping: Mapping | None, explanation: Sequence, preload: float
) -> dict:
    """Return results/gap/updated_model.json with the damping at test level where the records call for it.

    The damping at test level is summary.json's ``friction.test_damping`` (rule test_damping). It is applied where
    the records call for it and nothing else explains their gap: the held-out load cases confirmed the factor
    (``accepted``), the explanation names no effect (``story.effect_steps``; an effect's refit is the model then) and
    the diagnosed model is the chain's (the factor was weighed on the chain's structure, not an update of it). The
    model then carries the factor, the friction law fitted with it and the held-out gap it leaves; otherwise
    ``damping_at_test_level`` says why it is not applied.

    Parameters
    ----------
    updated
        updated_model.json as ``updated_model_summary`` writes it.
    test_damping
        summary.json's ``friction.test_damping``: reads ``accepted``, ``law`` ({parameter: value}), ``reason`` and
        ``heldout_gap_test_damping``; None or empty: not profiled.
    explanation
        The explanation's steps.
    preload
        The preload N0 [N].

    Returns
    -------
    updated : dict
        ``updated`` unchanged where there is no test damping, with ``damping_at_test_level`` added (applied or why
        not) otherwise.
    """
    from .story import effect_steps

    if not test_damping:
        return updated
    td = dict(test_damping)
    if not td.get("accepted") or "law" not in td:
        why = td.get("reason", "not profiled")
    elif effect_steps(explanation):
        why = "the diagnosis explains the gap by an effect, refitted with the random test's damping"
    elif updated.get("model_updating"):
        why = "the structure was updated; the factor was weighed on the chain's structure"
    else:
        why = ""
    if why:
        return {**updated, "damping_at_test_level": {**td, "applied": False, "why": why}}
    law = np.array([td["law"][n] for n in PARAMETER_NAMES])
    return {
        **updated,
        "what": "the identified model with the damping at test level the records confirm (no effect explained), the "
        "friction law fitted with it on the calibration case",
        "damping_at_test_level": {**td, "applied": True, "why": td.get("reason", "")},
        "friction": _friction_dict(law, preload),
        "heldout_gap": float(td["heldout_gap_test_damping"]),
    }
