"""The blind benchmark's scores, from the items' result rows.

Top-1 accuracy, confusion matrix, false alarms and the leave-out results (``score``, ``confusion_figure``), the compound
items' (``compound_score``; the friction law's errors against the rig's truth, the effects an explanation names), the
detection ladder's (``ladder_score``) and the records' check's false alarms (``records_check_score``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from .bench_items import EXPECTED_PLACE
from .story import effect_steps

if TYPE_CHECKING:
    from .model import IdentifiedModel

# candidates that explain a contact effect (a perturbation-only set must name none of them); contact_separation
# changes the normal law's shape, which the perturbation's hardening also does, so it counts as model form
CONTACT_EFFECTS = ("normal_contact_damping", "viscous_friction", "multi_asperity_friction", "preload_drift")
# the friction intervals the compound items score: the law's, then what the data bind (gap.uncertainty.PRODUCTS)
SCORED_INTERVALS = ("mu", "kappa", "e0", "mu_a", "e0_a2")


def records_check_score(rows: list) -> dict:
    """Return how often the records' check called the benchmark's (right) records wrong.

    Its findings with a signature (false alarms, which would make the verdict records_disagree) and its gross warnings,
    over the items it ran on.

    Parameters
    ----------
    rows
        The items' result rows (``benchmark``'s dicts); those with a ``records_check`` mapping count.

    Returns
    -------
    scores : dict
        {"items": items the check ran on, "false_alarms": items it did not pass, "gross_warnings": items with a
        gross finding}.
    """
    ran = [r["records_check"] for r in rows if isinstance(r.get("records_check"), Mapping)]
    return {
        "items": len(ran),
        "false_alarms": sum(not c["passed"] for c in ran),
        "gross_warnings": sum("gross" in c["findings"] for c in ran),
    }


def score(rows: list) -> dict:
    """Return top-1 accuracy, confusion matrix, false alarms, shrink and the leave-out results.

    Parameters
    ----------
    rows
        The items' result rows (``benchmark``'s dicts, kinds blind, effect_free, leave_out and compound; failed
        items listed apart).

    Returns
    -------
    scores : dict
        The scores: n_blind, top1_accuracy [-], n_effect_free, false_alarms, shrink_of_correct (min and median [-],
        and whether all are at least a half), leave_out (counts and items), confusion (true effect -> verdict ->
        count), per_effect_accuracy [-], diagnosis_seconds (median and max [s]), compound (``compound_score``, where
        there are compound items), failed and two_stories.
    """
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
    from .place import acts_where

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
    """Return the detection ladder's scores, per item and overall.

    An item is detectable when the identified model's held-out gap (before model updating, which may take up a
    transducer-mass effect) exceeds twice the floor (``gap.min_gap``); there the effect must be the verdict and its
    refitted magnitude within ``tolerance`` of the truth (where the two are comparable, ``refitted_magnitude``).

    Parameters
    ----------
    rows
        The ladder items' result rows (``benchmark``'s dicts).
    floor
        The floor, ``gap.min_gap``: the relative held-out gap the chain's own identification leaves [-].
    tolerance
        Largest relative error of a refitted magnitude against the truth [-].

    Returns
    -------
    scores : dict
        Counts (n, n_failed, n_detectable, false_names_below_detectable, two_stories), ``floor`` and ``tolerance``,
        the shares named_where_detectable and magnitude_within_where_detectable [-], all_named_and_within, and per
        item its row (magnitude_error relative [-]).
    """
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
    """Draw the heat map of the confusion matrix (rows: true effect, columns: verdict).

    Parameters
    ----------
    result
        The scores of ``score`` (its ``confusion``, ``top1_accuracy``, ``n_blind``, ``false_alarms`` and
        ``n_effect_free``).
    path
        The figure's file (PNG).
    """
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


def friction_truth(truth_friction: Mapping, preload: float, lever_arm: float | None = None) -> dict:
    """Return the rig's true mu, kappa and e_0 at the preload (Eq. 22), and with its lever arm what the data bind.

    Given the rig's true tangential ``lever_arm`` a, also what the data bind: mu a and e_0 a^2.

    Parameters
    ----------
    truth_friction
        The rig's true friction law (config ``rig.truth.friction``: mu, kappa, e_f_n_per_m, k_c_per_m).
    preload
        The static normal preload [N].
    lever_arm
        The rig's true tangential lever arm a [m], or None.

    Returns
    -------
    truth : dict
        {"mu": [-], "kappa": [-], "e0": [N/m]}, and with ``lever_arm`` also {"mu_a": [m], "e0_a2": [N m]}.
    """
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


def friction_errors(model: IdentifiedModel, truth_friction: Mapping, preload: float) -> dict:
    """Return the relative errors of the model's mu, kappa and e_0 at the preload against the rig's truth.

    Parameters
    ----------
    model
        The model whose friction law is scored (its ``friction``: e_f, k_c, e_t, kappa, mu).
    truth_friction
        The rig's true friction law (config ``rig.truth.friction``, as ``friction_truth`` reads it).
    preload
        The static normal preload [N].

    Returns
    -------
    errors : dict
        {"mu", "kappa", "e0"}: each the model's value over the truth's, less one [-].
    """
    from ..contact_laws import stiction_shear_stiffness

    e_f, k_c, _, kappa, mu = model.friction
    t = friction_truth(truth_friction, preload)
    e0 = stiction_shear_stiffness(preload, e_f, k_c)
    return {"mu": float(mu / t["mu"] - 1), "kappa": float(kappa / t["kappa"] - 1), "e0": float(e0 / t["e0"] - 1)}


def bound_errors(model: IdentifiedModel, truth_friction: Mapping, preload: float, true_lever_arm: float) -> dict:
    """Return the relative errors of what the data bind when the tangential lever arm a is unknown.

    The products mu a and e_0 a^2 (``contactid.gap.uncertainty``), the model's a against the rig's true a.

    Parameters
    ----------
    model
        The model whose friction law and lever arm are scored (its ``friction`` and
        ``structure.tangential_lever_arm``).
    truth_friction
        The rig's true friction law (config ``rig.truth.friction``, as ``friction_truth`` reads it).
    preload
        The static normal preload [N].
    true_lever_arm
        The rig's true tangential lever arm a [m].

    Returns
    -------
    errors : dict
        {"mu_a", "e0_a2"}: each the model's product over the truth's, less one [-].
    """
    err = friction_errors(model, truth_friction, preload)
    r = model.structure.tangential_lever_arm / float(true_lever_arm)
    return {"mu_a": float((1 + err["mu"]) * r - 1), "e0_a2": float((1 + err["e0"]) * r**2 - 1)}


def named_effects(explanation: Sequence[Mapping]) -> list:
    """Return the effects an explanation names (``story.effect_steps``), an update by the effect it names.

    Parameters
    ----------
    explanation
        The diagnosis's explanation steps (diagnosis.json ``explanation``).

    Returns
    -------
    effects : list
        The named effects, in the explanation's order.
    """
    return [s.get("names", s["effect"]) for s in effect_steps(explanation)]


def compound_score(rows: list) -> dict:
    """Return the scores of the compound items (see config/README.md, gap_benchmark.compound).

    Parameters
    ----------
    rows
        The compound items' result rows (``benchmark.compound_row``'s dicts).

    Returns
    -------
    scores : dict
        Counts, the shares of items whose named effects are right [-], per effect its recall and precision [-], the
        median remaining gap [-], the share with an accepted update [-], and for the perturbation-only items the
        friction law's median absolute relative errors [-], its intervals' coverage [-] and median relative
        half-widths [-].
    """

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
