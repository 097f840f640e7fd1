"""The blind check of the diagnosis: rig data sets with one effect on at a random (seeded)
magnitude, diagnosed from their raw records alone, and scored.

Items (config ``gap_benchmark``): for every effect, ``magnitudes`` random magnitudes in its
benchmark range for every seed in ``seeds``; one effect-free data set per seed (false alarms);
and, with ``leave_out``, for every effect one data set at mid-range diagnosed with a library that
lacks that effect (the verdict must be "none", the localisation must point at the right place);
and ``compound`` items per seed: a rig whose structure, normal law and damping differ from the model's
at random, with 0, 1 or 2 effects, diagnosed with model updating and scored on the additive explanation.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..config import schema_defaults
from ..random_streams import generator
from ..rig.effects import EFFECTS
from .story import effect_steps, one_story_holds

log = logging.getLogger(__name__)

# magnitudes the benchmark draws from (rig units, see rig.effects): large enough to matter,
# within the range where the rig's response stays periodic
RANGES = {
    "structural_damping": (0.002, 0.01),
    "normal_contact_damping": (150.0, 600.0),
    "viscous_friction": (150.0, 600.0),
    "multi_asperity_friction": (0.5, 1.0),
    "transducer_mass_error": (0.15, 0.5),
    "channel_time_skew": (1.0e-5, 4.0e-5),
    "channel_gain_error": (0.015, 0.05),  # channels 0.5-5 % off: a calibration's tolerance
    "contact_separation": (5.05, 5.2),  # lc3 (1.43 x lc1) separates; above, its motion stops settling
    "preload_drift": (0.05, 0.2),
}

# where the localisation should point when the effect is missing from the library
EXPECTED_PLACE = {
    "structural_damping": "structure_or_measurement",
    "transducer_mass_error": "structure_or_measurement",
    "channel_time_skew": "structure_or_measurement",
    "channel_gain_error": "structure_or_measurement",
    "normal_contact_damping": "normal_contact",
    "contact_separation": "normal_contact",
    "viscous_friction": "tangential_contact",
    "multi_asperity_friction": "tangential_contact",
    "preload_drift": "non_stationary",
}


def benchmark_items(cfg: Mapping, seed: int) -> dict:
    """{name: spec} with spec = {effect, magnitude, seed, library (None = all), kind}; ``cfg`` the gap_benchmark
    block (keys left out: the schema's defaults)."""
    cfg = {**schema_defaults("gap_benchmark"), **dict(cfg or {})}
    effects = cfg.get("effects") or list(EFFECTS)
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown:
        raise ValueError(f"gap_benchmark.effects: unknown {unknown}; known: {', '.join(EFFECTS)}")
    ranges = {**RANGES, **{k: tuple(v) for k, v in (cfg.get("ranges") or {}).items()}}
    n_mag = int(cfg["magnitudes"])
    seeds = [int(s) for s in cfg["seeds"]]
    items = {}
    for e in effects:
        lo, hi = ranges[e]
        for s in seeds:
            for k in range(n_mag):
                m = float(generator(seed, f"gap_benchmark/{e}/{k}/{s}").uniform(lo, hi))
                items[f"{e}-{k}-s{s}"] = {"effect": e, "magnitude": m, "seed": s, "library": None, "kind": "blind"}
    for s in seeds[: int(cfg["effect_free"])]:
        items[f"none-0-s{s}"] = {"effect": None, "magnitude": 0.0, "seed": s, "library": None, "kind": "effect_free"}
    if cfg["leave_out"]:
        for e in effects:
            lo, hi = ranges[e]
            lib = [x for x in EFFECTS if x != e]
            items[f"lo_{e}-0-s{seeds[0]}"] = {
                "effect": e,
                "magnitude": 0.5 * (lo + hi),
                "seed": seeds[0],
                "library": lib,
                "kind": "leave_out",
            }
    items.update(compound_items(int(cfg["compound"]), seeds, seed, ranges))
    return items


def expected_seconds(spec: Mapping) -> int:
    """A benchmark item's expected run time (s, on one core of the 2-core reference machine; the blind benchmark
    at 4e9292c), for the workflow's scheduler to start the long items first so that no core idles at the end
    waiting for one of them (``gap_benchmark_item``'s priority). The rig's truth sets it: a preload drift in a
    compound item (its later passes march whole records: 30-75 s) and a contact that opens (every simulation
    marched from the linear state: 31-38 s) are the long ones; most items take 10-20 s."""
    effects = dict(spec.get("effects") or {})
    if spec.get("effect"):
        effects[spec["effect"]] = spec.get("magnitude", 0.0)
    if spec.get("kind") == "compound":
        return 35 if "preload_drift" in effects else 20
    if "contact_separation" in effects and spec.get("kind") != "leave_out":
        return 33 if spec.get("fraction", 1.0) > 0.5 else 12
    return 18 if spec.get("kind") == "leave_out" else 11


def ladder_typical(effect: str, ranges: Mapping = RANGES) -> float:
    """An effect's typical magnitude (``rig.effects``' typical value), kept inside its benchmark range's upper
    end (contact separation's typical 7.2 makes lc3's impacts keep the motion from settling)."""
    return float(min(EFFECTS[effect].typical, ranges[effect][1]))


def ladder_items(cfg: Mapping, seed: int) -> dict:
    """{name: spec} of the detection ladder (config gap_benchmark.ladder: fractions of each effect's typical
    magnitude, for every seed): single-effect items named ``ladder_<effect>-<k>-s<seed>``."""
    cfg = {**schema_defaults("gap_benchmark"), **dict(cfg or {})}
    fractions = [float(f) for f in cfg["ladder"]]
    effects = cfg.get("effects") or list(EFFECTS)
    ranges = {**RANGES, **{k: tuple(v) for k, v in (cfg.get("ranges") or {}).items()}}
    items = {}
    for e in effects:
        for s in [int(x) for x in cfg.get("seeds", [1, 2])]:
            for k, f in enumerate(fractions):
                items[f"ladder_{e}-{k}-s{s}"] = {
                    "effect": e,
                    "magnitude": f * ladder_typical(e, ranges),
                    "seed": s,
                    "library": None,
                    "kind": "ladder",
                    "fraction": f,
                }
    return items


def refitted_magnitude(effect: str, parameters: Mapping | None) -> float | None:
    """The rig magnitude a candidate's refitted parameters amount to (None where the two are not comparable:
    contact separation's rig magnitude is a load factor, the candidate's a normal-law shape). Channel skew: the
    rig delays channel k of n by m (k + 1) / n; m is the least-squares fit of the refitted per-channel delays.
    Channel gains: the rig reads channel k of n with 1 + m (-1)^k (k + 1) / n; m is the least-squares fit of the
    refitted gain errors."""
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
    """The rig magnitude the diagnosis refitted for ``effect`` (``refitted_magnitude`` of its candidate); an accepted
    model update's transducer-mass factor counts for transducer_mass_error (the candidate refits what is left)."""
    if effect not in ranking:
        return None
    m = refitted_magnitude(effect, ranking[effect].get("parameters"))
    if effect == "transducer_mass_error" and m is not None and updating is not None and updating.accepted:
        m = updating.factors.get("transducer_mass_scale", 1.0) * (1.0 + m) - 1.0
    return m


def item_config(cfg: Mapping, spec: Mapping) -> tuple[dict, dict]:
    """The config of an item's rig (a compound item's perturbed as ``compound_config`` says) and the effects it hides
    {effect: magnitude (rig units)}; ``cfg``: the base config with the schema's defaults."""
    effects = {spec["effect"]: spec["magnitude"]} if spec["effect"] else {}
    if spec["kind"] == "compound":
        cfg = compound_config(cfg, spec)
        effects = dict(spec["effects"])
    return cfg, effects


def hidden_text(spec: Mapping, effects: Mapping) -> str:
    """What an item hides, in words (for the log)."""
    hidden = f"{spec['effect']} at {spec['magnitude']:.4g}" if spec["effect"] else "no effect"
    if spec["kind"] == "compound":
        hidden = "perturbed rig with " + (", ".join(f"{e} at {m:.4g}" for e, m in effects.items()) or "no effect")
    return hidden


def nonfinite_records(recs: Mapping) -> list:
    """The names of the rig records whose acceleration or force is not finite everywhere."""
    return [
        n
        for n, ds in recs.items()
        if not (np.isfinite(ds["acceleration"].values).all() and np.isfinite(ds["force"].values).all())
    ]


def failed_row(spec: Mapping, bad: list, converged, t_rig: float) -> dict:
    """The result row of an item whose rig records are not finite (not diagnosed, scored apart); ``t_rig`` in s."""
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
    """An item's identification and diagnosis: the diagnosis, the model it diagnosed (after model updating) and the
    chain's, the model update (None: off), the records' harmonics {case: record}, the friction fit's settings; the
    identification's time, the diagnosis' start (``time.perf_counter``) and its time, in s."""

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
    """Identify the model from an item's rig records ``recs`` (the chain, then model updating) and diagnose it with
    the item's library; ``t0`` the item's start (``time.perf_counter``, s), ``t_rig`` the rig's time (s)."""
    from ..friction_fit import settings_from_config
    from .diagnosis import GapSettings, diagnose
    from .localise import linear_stage, random_test_delays
    from .pipeline import identify, updated_model
    from .records import record_harmonics

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


def compound_row(spec: Mapping, cfg: Mapping, effects: Mapping, item: ItemDiagnosis, converged, t_rig: float) -> dict:
    """A compound item's result row: the additive explanation scored against the hidden ``effects``, the friction
    law's errors (relative) and its intervals with the model-form term; seconds of each step."""
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


def blind_row(spec: Mapping, item: ItemDiagnosis, converged, t_rig: float) -> dict:
    """A single-effect (blind, effect-free, left-out or ladder) item's result row: the verdict against the hidden
    effect, the true effect's held-out gap, refitted magnitude and shrink, the ranking; seconds of each step."""
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
    """An item's diagnosis as ``snakemake gap`` writes it: ``outputs["diagnosis"]`` (diagnosis.json, with the item's
    spec under ``benchmark_item``) and ``outputs["dataset"]`` (gap.nc), from which ``gap_benchmark_figures`` draws
    every gap figure and the report's gap section; ``n_harmonics``: the harmonics the diagnosis compares
    (gap.n_harmonics). An item the rig could not simulate (``item`` None) gets a diagnosis.json that says so
    (``failed``) and a gap.nc without variables."""
    import json

    import xarray as xr

    from ..io import write_dataset, write_text
    from .output import _clean, diagnosis_json, gap_dataset

    if item is None:
        write_text(outputs["diagnosis"], json.dumps(_clean({"failed": failed, "benchmark_item": dict(spec)}), indent=2))
        write_dataset(xr.Dataset(attrs={"failed": failed}), outputs["dataset"])
        return
    extra = {"seconds": item.t_diag, "benchmark_item": dict(spec)}
    write_dataset(gap_dataset(item.diag, item.records, int(n_harmonics)), outputs["dataset"])
    write_text(outputs["diagnosis"], diagnosis_json(item.diag, extra))


def run_item(spec: Mapping, cfg: Mapping, outputs: Mapping | None = None) -> dict:
    """Generate the item's rig records, identify the model from them, diagnose; the result row. ``cfg``: the base
    config (keys left out: the schema's defaults). ``outputs`` ({"diagnosis": path, "dataset": path}, optional):
    where to write the item's diagnosis.json and gap.nc (``write_item_diagnosis``)."""
    from ..config import with_defaults
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
    """The records' check (rule record_checks) of an item's records against its chain model: every rig record is
    right, so a finding with a signature is a false alarm of the check ({passed, checks named})."""
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


def records_check_score(rows: list) -> dict:
    """How often the records' check called the benchmark's (right) records wrong: findings with a signature (false
    alarms, which would make the verdict records_disagree) and gross warnings, over the items it ran on."""
    ran = [r["records_check"] for r in rows if isinstance(r.get("records_check"), Mapping)]
    return {
        "items": len(ran),
        "false_alarms": sum(not c["passed"] for c in ran),
        "gross_warnings": sum("gross" in c["findings"] for c in ran),
    }


def score(rows: list) -> dict:
    """Top-1 accuracy, confusion matrix, false alarms, shrink and the leave-out results."""
    failed = [r for r in rows if r.get("failed")]
    rows = [r for r in rows if not r.get("failed")]
    comp = [r for r in rows if r["kind"] == "compound"]
    rows = [r for r in rows if r["kind"] != "compound"]
    blind = [r for r in rows if r["kind"] == "blind"]
    free = [r for r in rows if r["kind"] == "effect_free"]
    lo = [r for r in rows if r["kind"] == "leave_out"]
    labels = sorted({r["effect"] for r in blind}) + ["none"]
    conf = {t: {p: 0 for p in labels + sorted({r["verdict"] for r in rows} - set(labels))} for t in labels}
    for r in blind + free:
        conf[r["effect"] or "none"][r["verdict"]] = conf[r["effect"] or "none"].get(r["verdict"], 0) + 1
    correct = [r for r in blind if r["verdict"] == r["effect"]]
    shrink = [r["shrink_true"] for r in correct]
    place_ok = []
    from .verdict import acts_where

    for r in lo:  # "contact" (eta not observable) is right for a normal or tangential effect, if less specific
        place_ok.append(acts_where(EXPECTED_PLACE[r["effect"]], r["where"].get("place")))
    return {
        "n_blind": len(blind),
        "top1_accuracy": len(correct) / max(len(blind), 1),
        "n_effect_free": len(free),
        "false_alarms": sum(r["verdict"] != "none" for r in free),
        "shrink_of_correct": {
            "min": float(np.min(shrink)) if shrink else None,
            "median": float(np.median(shrink)) if shrink else None,
            "all_at_least_half": bool(shrink) and all(s >= 0.5 for s in shrink),
        },
        "leave_out": {
            "n": len(lo),
            "verdict_none": sum(r["verdict"] == "none" for r in lo),
            "place_right": int(sum(place_ok)),
            "items": [
                {
                    "effect": r["effect"],
                    "verdict": r["verdict"],
                    "place": r["where"].get("place"),
                    "expected_place": EXPECTED_PLACE[r["effect"]],
                    "direction": r["where"].get("direction"),
                    "largest_stage": r["where"].get("largest_stage"),
                    "harmonic_class": r["where"].get("harmonic_class"),
                }
                for r in lo
            ],
        },
        "confusion": conf,
        "per_effect_accuracy": {
            e: float(np.mean([r["verdict"] == e for r in blind if r["effect"] == e])) for e in labels if e != "none"
        },
        "diagnosis_seconds": {
            "median": float(np.median([r["seconds"]["diagnosis"] for r in rows])) if rows else None,
            "max": float(np.max([r["seconds"]["diagnosis"] for r in rows])) if rows else None,
        },
        **({"compound": compound_score(comp)} if comp else {}),
        "failed": [{k: r.get(k) for k in ("kind", "effect", "effects", "seed", "failed")} for r in failed],
        "two_stories": [
            {k: r.get(k) for k in ("kind", "effect", "effects", "seed", "verdict")}
            for r in [*rows, *comp]
            if not r.get("one_story", True)
        ],
    }


def ladder_score(rows: list, floor: float, tolerance: float = 0.25) -> dict:
    """The detection ladder: an item is detectable when the identified model's held-out gap (before model updating,
    which may take up a transducer-mass effect) exceeds twice the floor (``gap.min_gap``); there the effect must
    be the verdict and its refitted magnitude within ``tolerance`` of the truth (where the two are comparable,
    ``refitted_magnitude``). Per item and overall."""
    items = []
    for r in rows:
        if r.get("failed"):
            items.append(
                {"item": r.get("item"), "effect": r["effect"], "fraction": r.get("fraction"), "failed": r["failed"]}
            )
            continue
        gap = r.get("heldout_gap_identified", r["heldout_gap_before"])
        detectable = bool(gap > 2.0 * floor)
        m = r.get("refitted_magnitude")
        err = None if m is None or not r["magnitude"] else float(m / r["magnitude"] - 1.0)
        items.append(
            {
                "item": r.get("item"),
                "effect": r["effect"],
                "fraction": r.get("fraction"),
                "seed": r["seed"],
                "magnitude": r["magnitude"],
                "heldout_gap_before": gap,
                "detectable": detectable,
                "verdict": r["verdict"],
                "named": r["verdict"] == r["effect"],
                "one_story": r.get("one_story", True),
                "refitted_magnitude": m,
                "magnitude_error": err,
                "magnitude_within": None if err is None else bool(abs(err) <= tolerance),
            }
        )
    det = [i for i in items if i.get("detectable")]
    comparable = [i for i in det if i["magnitude_within"] is not None]
    share = lambda xs: float(np.mean(xs)) if xs else None  # noqa: E731
    return {
        "n": len(items),
        "n_failed": sum("failed" in i for i in items),
        "floor": floor,
        "tolerance": tolerance,
        "n_detectable": len(det),
        "named_where_detectable": share([i["named"] for i in det]),
        "magnitude_within_where_detectable": share([i["magnitude_within"] for i in comparable]),
        "all_named_and_within": bool(det) and all(i["named"] and i["magnitude_within"] is not False for i in det),
        "false_names_below_detectable": sum(
            i["verdict"] not in ("none", i["effect"]) for i in items if "failed" not in i and not i["detectable"]
        ),
        "two_stories": sum(not i.get("one_story", True) for i in items),
        "items": items,
    }


def confusion_figure(result: dict, path: str) -> None:
    """Heat map of the confusion matrix (rows: true effect, columns: verdict)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = list(result["confusion"])
    cols = sorted({c for r in result["confusion"].values() for c in r}, key=lambda c: (c == "none", c))
    M = np.array([[result["confusion"][r].get(c, 0) for c in cols] for r in rows])
    fig, ax = plt.subplots(figsize=(7.5, 6))
    ax.imshow(M, cmap="Blues")
    for i in range(M.shape[0]):
        for j in range(M.shape[1]):
            if M[i, j]:
                ax.text(j, i, str(M[i, j]), ha="center", va="center", color="k")
    ax.set_xticks(range(len(cols)), cols, rotation=60, ha="right")
    ax.set_yticks(range(len(rows)), rows)
    ax.set_xlabel("verdict")
    ax.set_ylabel("effect on in the rig")
    ax.set_title(
        f"Blind benchmark: top-1 {result['top1_accuracy']:.0%} of {result['n_blind']}, "
        f"false alarms {result['false_alarms']}/{result['n_effect_free']}"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


# ------------------------------------------------------------------------------------------
# compound items: a perturbed rig (its truth is not the model) with 0, 1 or 2 effects
# ------------------------------------------------------------------------------------------

# the effects a compound item may add (transducer masses are perturbed anyway; contact_separation is a load
# factor that may keep a perturbed rig from settling), by the place they act
COMPOUND_EFFECTS = {
    "tangential_contact": ("viscous_friction", "multi_asperity_friction"),
    "normal_contact": ("normal_contact_damping",),
    "structure_or_measurement": ("structural_damping", "channel_time_skew"),
    "non_stationary": ("preload_drift",),
}
# candidates that explain a contact effect (a perturbation-only set must name none of them); contact_separation
# changes the normal law's shape, which the perturbation's hardening also does, so it counts as model form
CONTACT_EFFECTS = ("normal_contact_damping", "viscous_friction", "multi_asperity_friction", "preload_drift")
# the friction intervals the compound items score: the law's, then what the data bind (gap.uncertainty.PRODUCTS)
SCORED_INTERVALS = ("mu", "kappa", "e0", "mu_a", "e0_a2")
PERTURBATION = {"youngs_modulus": 0.03, "transducer_masses": 0.4, "tangential_lever_arm": 0.08}
HARDENING_CUBIC = (2.0e19, 6.0e19)  # N/m^3 of the polynomial hardening N0 - k_n eta - k_3 eta^3
# N m/rad, log-uniform, of a clamp that gives (on half the compound rigs): the modes' frequencies lower and their shapes
# at the sensors changed much as relative channel gains change them (docs/gap.md, "Model updating")
CLAMP_STIFFNESS = (1.0e5, 1.0e6)
DAMPING_FORMS = ("modal", "stiffness_proportional", "mass_proportional")
# a compound rig's friction law away from Table 4's (log-uniform): mu and kappa themselves, e_f and k_c as factors on
# the configured truth's (the other simulator's other law: mu 0.33, kappa 0.25, e_f x 1.17, k_c x 0.82)
FRICTION_LAW_RANGES = {"mu": (0.28, 0.48), "kappa": (0.15, 0.42), "e_f_factor": (0.6, 1.7), "k_c_factor": (0.7, 1.4)}
# on a third of the compound rigs every damping ratio differs in the dual-sine tests from the random test's by this
# factor (uniform; rig.true_damping.dual_sine_factor): a damping that changes with level
DUAL_SINE_DAMPING = (0.85, 1.15)


def compound_items(n_per_seed: int, seeds, seed: int, ranges: Mapping) -> dict:
    """{name: spec} of the compound items: item k of each seed perturbs the rig's structure at random (E
    +-3 %, transducer masses +-40 %, lever arm +-8 %; polynomial hardening on or off; a damping form; on half of them a
    clamp that gives, CLAMP_STIFFNESS; on half a friction law away from Table 4's, FRICTION_LAW_RANGES; on a third
    Eq. 21 read with the slip limit; on a third the damping in the dual-sine tests other than in the random test,
    DUAL_SINE_DAMPING) and adds
    k mod 3 effects (two in different places), each at a random magnitude in its benchmark range."""
    items = {}
    places = list(COMPOUND_EFFECTS)
    for s in seeds:
        for k in range(int(n_per_seed)):
            rng = generator(seed, f"gap_benchmark/compound/{k}/{s}")
            pert = {name: float(rng.uniform(-a, a)) for name, a in PERTURBATION.items()}
            hardening = bool(rng.random() < 0.5)
            cubic = float(rng.uniform(*HARDENING_CUBIC)) if hardening else 0.0
            form = DAMPING_FORMS[int(rng.integers(len(DAMPING_FORMS)))]
            n_eff = k % 3
            chosen = rng.choice(len(places), size=n_eff, replace=False) if n_eff else []
            effects = {}
            for i in chosen:
                options = COMPOUND_EFFECTS[places[int(i)]]
                e = options[int(rng.integers(len(options)))]
                lo, hi = ranges[e]
                effects[e] = float(rng.uniform(lo, hi))
            # drawn last, so that the draws above (and the items before the clamp was added) stay as they were
            clamp = float(np.exp(rng.uniform(*np.log(CLAMP_STIFFNESS)))) if rng.random() < 0.5 else None
            # drawn after the clamp, for the same reason: on half the rigs a friction law away from Table 4's (the
            # identified law's form holds, its values do not), on a third Eq. 21 read with the slip limit
            law = (
                {k: float(np.exp(rng.uniform(*np.log(r)))) for k, r in FRICTION_LAW_RANGES.items()}
                if rng.random() < 0.5
                else None
            )
            regularization = "slip_limit" if rng.random() < 1.0 / 3.0 else "none"
            # drawn last, for the same reason
            dual_sine = float(rng.uniform(*DUAL_SINE_DAMPING)) if rng.random() < 1.0 / 3.0 else 1.0
            items[f"compound-{k}-s{s}"] = {
                "kind": "compound",
                "seed": int(s),
                "effect": None,
                "magnitude": 0.0,
                "library": None,
                "effects": effects,
                "perturbation": pert,
                "normal_cubic_n_per_m3": cubic,
                "damping_form": form,
                "clamp_rotational_stiffness_nm_per_rad": clamp,
                "friction_law": law,
                "friction_regularization": regularization,
                "dual_sine_damping_factor": dual_sine,
            }
    return items


def compound_config(cfg: Mapping, spec: Mapping) -> dict:
    """The config of a compound item's rig: rig.true_structure (with its clamp), the normal law, the damping form, the
    friction law's values and its reading of Eq. 21 perturbed as ``spec`` says (the identification keeps
    ``structure`` and ``friction``)."""
    import copy

    out = copy.deepcopy(dict(cfg))
    st, p = out["structure"], spec["perturbation"]
    rig = out["rig"]
    rig["true_structure"] = {
        "beam": {"youngs_modulus_pa": st["beam"]["youngs_modulus_pa"] * (1 + p["youngs_modulus"])},
        "sensors": {"masses_kg": [m * (1 + p["transducer_masses"]) for m in st["sensors"]["masses_kg"]]},
        "force_transducer_mass_kg": st["force_transducer_mass_kg"] * (1 + p["transducer_masses"]),
        "contact_geometry": {
            "tangential_lever_arm_m": st["contact_geometry"]["tangential_lever_arm_m"] * (1 + p["tangential_lever_arm"])
        },
    }
    if spec.get("clamp_rotational_stiffness_nm_per_rad"):
        rig["true_structure"]["clamp_rotational_stiffness_nm_per_rad"] = float(
            spec["clamp_rotational_stiffness_nm_per_rad"]
        )
    if spec["normal_cubic_n_per_m3"]:
        rig["truth"]["normal"] = {
            **rig["truth"]["normal"],
            "exponent": 1.0,
            "cubic_n_per_m3": float(spec["normal_cubic_n_per_m3"]),
        }
    rig["true_damping"] = {
        "form": spec["damping_form"],
        "reference_frequency_hz": 54.4,
        "dual_sine_factor": float(spec.get("dual_sine_damping_factor", 1.0)),
    }
    law, fr = spec.get("friction_law"), dict(rig["truth"]["friction"])
    if law:
        fr.update(
            mu=law["mu"],
            kappa=law["kappa"],
            e_f_n_per_m=fr["e_f_n_per_m"] * law["e_f_factor"],
            k_c_per_m=fr["k_c_per_m"] * law["k_c_factor"],
        )
    if spec.get("friction_regularization"):
        fr["regularization"] = spec["friction_regularization"]
    rig["truth"]["friction"] = fr
    return out


def friction_truth(truth_friction: Mapping, preload: float, lever_arm: float | None = None) -> dict:
    """The rig's true mu, kappa and e_0 at the preload (N/m, Eq. 22), and with its true tangential ``lever_arm`` (m)
    what the data bind: mu a (m) and e_0 a^2 (N m)."""
    from ..contact_laws import stiction_shear_stiffness

    t = truth_friction
    out = {
        "mu": float(t["mu"]),
        "kappa": float(t["kappa"]),
        "e0": float(stiction_shear_stiffness(preload, t["e_f_n_per_m"], t["k_c_per_m"])),
    }
    if lever_arm is not None:
        out |= {"mu_a": out["mu"] * float(lever_arm), "e0_a2": out["e0"] * float(lever_arm) ** 2}
    return out


def friction_errors(model, truth_friction: Mapping, preload: float) -> dict:
    """Relative errors of the model's mu, kappa and e_0 at the preload against the rig's truth."""
    from ..contact_laws import stiction_shear_stiffness

    e_f, k_c, _, kappa, mu = model.friction
    t = friction_truth(truth_friction, preload)
    e0 = stiction_shear_stiffness(preload, e_f, k_c)
    return {"mu": float(mu / t["mu"] - 1), "kappa": float(kappa / t["kappa"] - 1), "e0": float(e0 / t["e0"] - 1)}


def bound_errors(model, truth_friction: Mapping, preload: float, true_lever_arm: float) -> dict:
    """Relative errors of what the data bind when the tangential lever arm a is unknown (``contactid.gap.uncertainty``):
    mu a and e_0 a^2, the model's a against the rig's true a."""
    err = friction_errors(model, truth_friction, preload)
    r = model.structure.tangential_lever_arm / float(true_lever_arm)
    return {"mu_a": float((1 + err["mu"]) * r - 1), "e0_a2": float((1 + err["e0"]) * r**2 - 1)}


def named_effects(explanation) -> list:
    """The effects an explanation names (``story.effect_steps``), an update by the effect it names."""
    return [s.get("names", s["effect"]) for s in effect_steps(explanation)]


def compound_score(rows: list) -> dict:
    """Scores of the compound items (see config/README.md, gap_benchmark.compound)."""

    def named(r):
        return set(named_effects(r["explanation"]))

    by_n = {n: [r for r in rows if len(r["effects"]) == n] for n in (0, 1, 2)}
    share = lambda xs: float(np.mean(xs)) if xs else None  # noqa: E731
    truth_effects = sorted({e for r in rows for e in r["effects"]} | {e for r in rows for e in named(r)})
    per_effect = {}
    for e in truth_effects:
        tp = sum(e in r["effects"] and e in named(r) for r in rows)
        fn = sum(e in r["effects"] and e not in named(r) for r in rows)
        fp = sum(e not in r["effects"] and e in named(r) for r in rows)
        per_effect[e] = {
            "recall": tp / (tp + fn) if tp + fn else None,
            "precision": tp / (tp + fp) if tp + fp else None,
            "true": tp + fn,
            "named": tp + fp,
        }
    errors = {k: [abs(r["friction_errors"][k]) for r in by_n[0]] for k in ("mu", "kappa", "e0")}
    bound = {k: [abs(r["bound_errors"][k]) for r in by_n[0] if r.get("bound_errors")] for k in ("mu_a", "e0_a2")}
    covered = {
        k: [bool(r["friction_covered"][k]) for r in by_n[0] if k in (r.get("friction_covered") or {})]
        for k in SCORED_INTERVALS
    }
    width = {
        k: [r["friction_interval_halfwidth"][k] for r in by_n[0] if k in (r.get("friction_interval_halfwidth") or {})]
        for k in SCORED_INTERVALS
    }
    return {
        "n": len(rows),
        "n_by_effect_count": {str(n): len(v) for n, v in by_n.items()},
        "perturbation_only_no_contact_effect": share([not (named(r) & set(CONTACT_EFFECTS)) for r in by_n[0]]),
        "one_effect_named": share([set(r["effects"]) <= named(r) for r in by_n[1]]),
        "one_effect_no_absent_contact_effect": share(
            [not ((named(r) - set(r["effects"])) & set(CONTACT_EFFECTS)) for r in by_n[1]]
        ),
        "two_effects_both_named": share([set(r["effects"]) <= named(r) for r in by_n[2]]),
        "two_effects_one_named": share([bool(set(r["effects"]) & named(r)) for r in by_n[2]]),
        "per_effect": per_effect,
        "remaining_gap_median": float(np.median([r["remaining_gap"]["heldout_gap"] for r in rows])) if rows else None,
        "updating_accepted": share([bool(r["updating_accepted"]) for r in rows]),
        "perturbation_only_median_abs_error": {k: float(np.median(v)) if v else None for k, v in errors.items()},
        "perturbation_only_median_abs_bound_error": {k: float(np.median(v)) if v else None for k, v in bound.items()},
        "perturbation_only_interval_coverage": {k: share(v) for k, v in covered.items()},
        "perturbation_only_median_interval_halfwidth": {
            k: float(np.median(v)) if v else None for k, v in width.items()
        },
    }
