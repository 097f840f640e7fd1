"""The blind check of the diagnosis: rig data sets diagnosed from their raw records alone, and scored.

The single-effect data sets have one effect on at a random (seeded) magnitude. Items (config ``gap_benchmark``): for
every effect, ``magnitudes`` random magnitudes in its benchmark range for every seed in ``seeds``; one effect-free
data set per seed (false alarms); and, with ``leave_out``, for every effect one data set at mid-range diagnosed with a
library that lacks that effect (the verdict must be "none", the localisation must point at the right place); and
``compound`` items per seed: a rig whose structure, normal law and damping differ from the model's at random, with 0,
1 or 2 effects, diagnosed with model updating and scored on the additive explanation.

This module runs one item: its rig records, the identification and diagnosis, and its result row. What the items are:
``bench_items``; how the result rows are scored: ``bench_scores``.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .bench_items import hidden_text, item_config
from .bench_scores import SCORED_INTERVALS, bound_errors, friction_errors, friction_truth, named_effects
from .story import one_story_holds

log = logging.getLogger(__name__)


def refitted_magnitude(effect: str, parameters: Mapping | None) -> float | None:
    """Return the rig magnitude a candidate's refitted parameters amount to.

    None where the two are not comparable: contact separation's rig magnitude is a load factor, the candidate's a
    normal-law shape. Channel skew: the rig delays channel k of n by m (k + 1) / n; m is the least-squares fit of the
    refitted per-channel delays. Channel gains: the rig reads channel k of n with 1 + m (-1)^k (k + 1) / n; m is the
    least-squares fit of the refitted gain errors.

    Parameters
    ----------
    effect
        The effect's name (``rig.effects.EFFECTS``).
    parameters
        The candidate's refitted parameters {name: value} (per-channel ones numbered by channel, ``delay_0``, ...),
        in the candidates' units; None or empty where not refitted.

    Returns
    -------
    magnitude : float | None
        The rig magnitude in the effect's unit (``rig.effects.EFFECTS``): [-] for structural_damping,
        multi_asperity_friction, transducer_mass_error, channel_gain_error and preload_drift, [s/m] for
        normal_contact_damping, [N s/m] for viscous_friction, [s] for channel_time_skew; None where not
        comparable or not refitted.
    """
    if not parameters:
        return None
    direct = {
        "structural_damping": "extra_damping_ratio",
        "normal_contact_damping": "alpha",
        "viscous_friction": "sigma_2",
        "multi_asperity_friction": "iwan_share",
        "transducer_mass_error": "mass_error",
        "preload_drift": "relative_drift",
    }
    if effect in direct:
        return float(parameters[direct[effect]])
    if effect in ("channel_time_skew", "channel_gain_error"):
        d = np.array([parameters[k] for k in sorted(parameters, key=lambda k: int(k.rsplit("_", 1)[1]))])
        shape = np.arange(1, d.size + 1) / d.size
        if effect == "channel_gain_error":
            shape = shape * (-1.0) ** np.arange(d.size)
        return float(d @ shape / (shape @ shape))
    return None


def _refitted(effect, ranking: Mapping, updating) -> float | None:
    """Return the rig magnitude the diagnosis refitted for ``effect`` (``refitted_magnitude`` of its candidate).

    An accepted model update's transducer-mass factor counts for transducer_mass_error (the candidate refits what is
    left).
    """
    if effect not in ranking:
        return None
    m = refitted_magnitude(effect, ranking[effect].get("parameters"))
    if effect == "transducer_mass_error" and m is not None and updating is not None and updating.accepted:
        m = updating.factors.get("transducer_mass_scale", 1.0) * (1.0 + m) - 1.0
    return m


def nonfinite_records(recs: Mapping) -> list:
    """Return the names of the rig records whose acceleration or force is not finite everywhere.

    Parameters
    ----------
    recs
        {name: raw record} (``pipeline.rig_records``), each with ``acceleration`` and ``force``.

    Returns
    -------
    names : list
        The names of the records with a NaN or infinite sample.
    """
    return [
        n
        for n, ds in recs.items()
        if not (np.isfinite(ds["acceleration"].values).all() and np.isfinite(ds["force"].values).all())
    ]


def failed_row(spec: Mapping, bad: list, converged: Mapping[str, int], t_rig: float) -> dict:
    """Return the result row of an item whose rig records are not finite (not diagnosed, scored apart).

    Parameters
    ----------
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    bad
        The names of the records that are not finite (``nonfinite_records``).
    converged
        {case: 1 where the rig's response control converged, else 0} (``pipeline.rig_records``).
    t_rig
        The time the rig's records took [s].

    Returns
    -------
    row : dict
        The spec with ``failed`` (why), ``verdict`` None, ``correct`` False, ``control_converged`` and
        ``seconds``.
    """
    return {
        **dict(spec),
        "failed": f"rig records not finite: {', '.join(bad)}",
        "verdict": None,
        "correct": False,
        "control_converged": converged,
        "seconds": {"rig": t_rig},
    }


@dataclass(frozen=True)
class ItemDiagnosis:
    """An item's identification and diagnosis.

    Attributes
    ----------
    diag
        The diagnosis (``diagnosis.Diagnosis``).
    model
        The model it diagnosed (``model.IdentifiedModel``, after model updating).
    chain_model
        The identification chain's own model (``model.IdentifiedModel``).
    updating
        The model update (``UpdatingResult``); None where model updating is off.
    records
        The records' harmonics {case: ``records.RecordHarmonics``}.
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    t_id
        The identification's time [s].
    t1
        The diagnosis' start, a ``time.perf_counter`` reading [s].
    t_diag
        The diagnosis' time [s].
    """

    diag: object
    model: object
    chain_model: object
    updating: object
    records: dict
    fit_settings: object
    t_id: float
    t1: float
    t_diag: float


def diagnose_item(spec: Mapping, cfg: Mapping, recs: Mapping, cases: list, t0: float, t_rig: float) -> ItemDiagnosis:
    """Identify the model from an item's rig records and diagnose it with the item's library.

    The identification is the chain's (``pipeline.identify``), then model updating (``base_model.updated_model``, the
    load cases other than the calibration case held out).

    Parameters
    ----------
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    cfg
        The item's config with the schema's defaults; ``nonlinear`` (calibration_case, n_harmonics), ``friction``,
        ``gap`` and ``seed`` are read, and the chain's sections by ``pipeline.identify``.
    recs
        {``random_test`` or case: raw record} (``pipeline.rig_records``).
    cases
        The load cases to diagnose.
    t0
        The item's start, a ``time.perf_counter`` reading [s].
    t_rig
        The time the rig's records took [s].

    Returns
    -------
    item : ItemDiagnosis
        The diagnosis, the models, the update, the records' harmonics and the times.
    """
    from ..friction_fit import settings_from_config
    from .base_model import updated_model
    from .diagnosis import diagnose
    from .localise import linear_stage, random_test_delays
    from .pipeline import identify
    from .records import record_harmonics
    from .settings import GapSettings

    cal = cfg["nonlinear"]["calibration_case"]
    model, modes, modal, frf = identify(cfg, recs["random_test"], recs[cal])
    K = int(cfg["nonlinear"]["n_harmonics"])
    fit_settings = settings_from_config(cfg["friction"])
    records = {c: record_harmonics(recs[c], c, K) for c in cases}
    t_id = time.perf_counter() - t0 - t_rig
    gap_cfg = dict(cfg.get("gap", {}))
    if spec.get("library") is not None:
        gap_cfg["candidates"] = list(spec["library"])
    settings = GapSettings.from_config(gap_cfg, int(cfg["seed"]), K)
    t1 = time.perf_counter()
    log.info(
        "model identified in %.1f s; diagnosing%s",
        t_id,
        "" if spec.get("library") is None else f" with a library that lacks {spec['effect']}",
    )
    chain_model = model
    held_out = {c: r for c, r in records.items() if c != cal}
    model, updating = updated_model(
        chain_model, modal, records[cal], fit_settings, settings, int(cfg["seed"]), held_out=held_out
    )
    diag = diagnose(
        model,
        records,
        cal,
        settings,
        fit_settings,
        linear_stage(model, frf, modal),
        identified=chain_model,
        updating=updating,
        channel_delays=random_test_delays(frf, modal),
    )
    t_diag = time.perf_counter() - t1
    return ItemDiagnosis(diag, model, chain_model, updating, records, fit_settings, t_id, t1, t_diag)


def compound_row(
    spec: Mapping, cfg: Mapping, effects: Mapping, item: ItemDiagnosis, converged: Mapping[str, int], t_rig: float
) -> dict:
    """Return a compound item's result row.

    The row holds the additive explanation scored against the hidden ``effects``, the friction law's errors
    (relative) and its intervals with the model-form term (``uncertainty.friction_uncertainty``); seconds of each
    step.

    Parameters
    ----------
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    cfg
        The item's config; ``nonlinear.calibration_case``, ``structure.preload_n``, ``seed``, ``rig.truth.friction``
        and ``rig.true_structure.contact_geometry.tangential_lever_arm_m`` are read.
    effects
        The effects the item's rig hides {effect: magnitude in its rig unit}.
    item
        The item's identification and diagnosis.
    converged
        {case: 1 where the rig's response control converged, else 0}.
    t_rig
        The time the rig's records took [s].

    Returns
    -------
    row : dict
        The spec with the verdict, the explanation, whether it names the hidden effects (``correct``), the held-out
        gaps, the friction law's relative errors, intervals, coverage and half-widths, and ``seconds``.
    """
    from .uncertainty import friction_uncertainty

    diag, model, updating = item.diag, item.model, item.updating
    cal = cfg["nonlinear"]["calibration_case"]
    named = named_effects(diag.explanation)
    preload = float(cfg["structure"]["preload_n"])
    t_unc = time.perf_counter()
    unc = friction_uncertainty(
        model,
        item.records,
        cal,
        item.fit_settings,
        int(cfg["seed"]),
        updating.posterior_structures() if updating is not None else (),
    )
    t_unc = time.perf_counter() - t_unc
    truth = cfg["rig"]["truth"]["friction"]
    true_arm = cfg["rig"]["true_structure"]["contact_geometry"]["tangential_lever_arm_m"]
    return {
        **dict(spec),
        "verdict": diag.verdict,
        "reason": diag.reason,
        "one_story": one_story_holds(diag.summary()),
        "explanation": diag.explanation,
        "remaining_gap": diag.remaining_gap,
        "named": named,
        "correct": set(named) == set(effects),
        "updating_accepted": bool(updating is not None and updating.accepted),
        "heldout_gap_before": diag.where.get("heldout_gap_identified", diag.where["heldout_gap_before"]),
        "friction_errors": friction_errors(model, truth, preload),
        "friction_errors_chain": friction_errors(item.chain_model, truth, preload),
        "bound_errors": bound_errors(model, truth, preload, true_arm),
        "friction_intervals": {n: [float(v) for v in unc.interval_of(n)[0]] for n in SCORED_INTERVALS},
        "friction_covered": unc.covers(friction_truth(truth, preload, true_arm)),
        "friction_interval_halfwidth": unc.relative_halfwidth(SCORED_INTERVALS),
        "where": diag.where,
        "control_converged": converged,
        "seconds": {
            "rig": t_rig,
            "identification": item.t_id,
            "diagnosis": time.perf_counter() - item.t1 - t_unc,
            "intervals": t_unc,
        },
    }


def blind_row(spec: Mapping, item: ItemDiagnosis, converged: Mapping[str, int], t_rig: float) -> dict:
    """Return a single-effect (blind, effect-free, left-out or ladder) item's result row.

    The row holds the verdict against the hidden effect, the true effect's held-out gap, refitted magnitude and
    shrink, the ranking; seconds of each step.

    Parameters
    ----------
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    item
        The item's identification and diagnosis.
    converged
        {case: 1 where the rig's response control converged, else 0}.
    t_rig
        The time the rig's records took [s].

    Returns
    -------
    row : dict
        The spec with the verdict, whether it is right (``correct``; a left-out item's must be "none"), the held-out
        gaps, the refitted magnitude (``refitted_magnitude``), the ranking and ``seconds``.
    """
    diag, true = item.diag, spec["effect"]
    by = {r["effect"]: r for r in diag.ranking}
    return {
        **dict(spec),
        "verdict": diag.verdict,
        "reason": diag.reason,
        "one_story": one_story_holds(diag.summary()),
        "explanation": [{k: s.get(k) for k in ("effect", "kind", "names", "share")} for s in diag.explanation],
        "correct": (diag.verdict == (true or "none")) if spec["kind"] != "leave_out" else diag.verdict == "none",
        "heldout_gap_before": diag.where["heldout_gap_before"],
        "heldout_gap_identified": diag.where.get("heldout_gap_identified", diag.where["heldout_gap_before"]),
        "heldout_gap_after_true": by[true]["heldout_gap_after"] if true in by else None,
        "refitted_magnitude": _refitted(true, by, item.updating),
        "shrink_true": by[true]["reduction"] if true in by else None,
        "ranking": [
            {k: r[k] for k in ("effect", "heldout_gap_before", "heldout_gap_after", "score", "reduction")}
            for r in diag.ranking
        ],
        "where": diag.where,
        "control_converged": converged,
        "seconds": {"rig": t_rig, "identification": item.t_id, "diagnosis": item.t_diag},
    }


def write_item_diagnosis(
    outputs: Mapping, spec: Mapping, item: "ItemDiagnosis | None", n_harmonics: int, failed: str = ""
) -> None:
    """Write an item's diagnosis as ``snakemake gap`` writes it.

    ``gap_benchmark_figures`` draws every gap figure and the report's gap section from them. An item the rig could
    not simulate (``item`` None) gets a diagnosis.json that says so (``failed``) and a gap.nc without variables.

    Parameters
    ----------
    outputs
        Where to write: ``outputs["diagnosis"]`` (diagnosis.json, with the item's spec under ``benchmark_item``) and
        ``outputs["dataset"]`` (gap.nc).
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    item
        The item's identification and diagnosis; None where the rig could not simulate it.
    n_harmonics
        The harmonics the diagnosis compares (gap.n_harmonics).
    failed
        Why the item was not diagnosed (with ``item`` None).
    """
    import json

    import xarray as xr

    from ..io import write_dataset, write_text
    from .output import diagnosis_json, gap_dataset, json_ready

    if item is None:
        write_text(
            outputs["diagnosis"], json.dumps(json_ready({"failed": failed, "benchmark_item": dict(spec)}), indent=2)
        )
        write_dataset(xr.Dataset(attrs={"failed": failed}), outputs["dataset"])
        return
    extra = {"seconds": item.t_diag, "benchmark_item": dict(spec)}
    write_dataset(gap_dataset(item.diag, item.records, int(n_harmonics)), outputs["dataset"])
    write_text(outputs["diagnosis"], diagnosis_json(item.diag, extra))


def run_item(spec: Mapping, cfg: Mapping, outputs: Mapping | None = None) -> dict:
    """Generate the item's rig records, identify the model from them, diagnose, and return the result row.

    Parameters
    ----------
    spec
        The item's spec (``bench_items``): ``kind`` (blind, effect_free, leave_out, ladder or compound), ``effect``,
        ``magnitude`` (the effect's rig unit), ``seed``, ``library`` (None: the whole library) and, for a compound
        item, ``effects`` and its perturbation.
    cfg
        The base config (keys left out: the schema's defaults); the item's rig is derived from it
        (``bench_items.item_config``).
    outputs
        {"diagnosis": path, "dataset": path}: where to write the item's diagnosis.json and gap.nc
        (``write_item_diagnosis``); None: not written.

    Returns
    -------
    row : dict
        The item's result row (``compound_row``, ``blind_row`` or ``failed_row``), with the records' check
        (``records_check``) where diagnosed.
    """
    from ..schema import with_defaults
    from .pipeline import rig_records

    t0 = time.perf_counter()
    cfg, effects = item_config(with_defaults(cfg), spec)
    cases = sorted(cfg["load_cases"], key=lambda c: int(c[2:]))
    n_harmonics = int(cfg["gap"]["n_harmonics"])  # what the diagnosis compares, and its gap.nc holds
    hidden = hidden_text(spec, effects)
    log.info(
        "benchmark item (%s, seed %d): %s; making the rig records of %s",
        spec["kind"],
        int(spec["seed"]),
        hidden,
        ", ".join(["random_test", *cases]),
    )
    recs, converged = rig_records(cfg, effects, int(spec["seed"]), cases)
    t_rig = time.perf_counter() - t0
    bad = nonfinite_records(recs)
    if bad:  # the rig could not simulate this data set: say so, score it apart
        log.warning(
            "benchmark item (%s): the rig's records of %s are not finite; not diagnosed", spec["kind"], ", ".join(bad)
        )
        if outputs:
            failed = f"the rig's records of {', '.join(bad)} are not finite"
            write_item_diagnosis(outputs, spec, None, n_harmonics, failed=failed)
        return failed_row(spec, bad, converged, t_rig)
    log.info("rig records made in %.1f s; identifying the model", t_rig)
    item = diagnose_item(spec, cfg, recs, cases, t0, t_rig)
    diag = item.diag
    if outputs:
        write_item_diagnosis(outputs, spec, item, n_harmonics)
    records_check = _records_check(cfg, item)
    if spec["kind"] == "compound":
        row = compound_row(spec, cfg, effects, item, converged, t_rig)
        log.info(
            "benchmark item (compound): %s -> explanation %s (remaining gap %.3g), mu error %.2g %%, %.1f s",
            hidden,
            ", ".join(["model_updating"] * row["updating_accepted"] + row["named"]) or "none",
            diag.remaining_gap["heldout_gap"],
            100 * row["friction_errors"]["mu"],
            time.perf_counter() - t0,
        )
        return {**row, "records_check": records_check}
    expected = "none" if spec["kind"] == "leave_out" else (spec["effect"] or "none")
    log.info(
        "benchmark item (%s): %s -> verdict %s (expected %s: %s), %.1f s in all",
        spec["kind"],
        hidden,
        diag.verdict,
        expected,
        "right" if diag.verdict == expected else "wrong",
        time.perf_counter() - t0,
    )
    return {**blind_row(spec, item, converged, t_rig), "records_check": records_check}


def _records_check(cfg: Mapping, item: ItemDiagnosis) -> dict:
    """Return the records' check (rule record_checks) of an item's records against its chain model.

    Every rig record is right, so a finding with a signature is a false alarm of the check ({passed, checks named}).
    """
    from .pipeline import records_check_of
    from .record_checks import Thresholds

    out = records_check_of(
        item.chain_model,
        item.records,
        cfg["nonlinear"]["calibration_case"],
        int(cfg["nonlinear"]["n_harmonics"]),
        Thresholds.from_config(cfg["gap"]["record_checks"]),
    )
    return {"passed": out["passed"], "findings": [f["check"] for f in out["findings"]]}
