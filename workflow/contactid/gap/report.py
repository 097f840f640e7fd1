"""The report's section on the sim-to-real gap: the diagnosis of the configured data and, when built,
the blind benchmark (text generated from diagnosis.json and benchmark.json, no number typed by hand)."""

from __future__ import annotations

import pandas as pd

from ..latex import _fmt, plain_text as _t, tabular
from .verdict import at_floor, never_opens


def _bound_text(c: dict) -> str:
    """The compound benchmark's errors of what the data bind (mu a, e_0 a^2), when scored."""
    b = c.get("perturbation_only_median_abs_bound_error")
    if not b or any(v is None for v in b.values()):
        return ""
    return (
        r" What the data bind, with the model's lever arm $a$ against the rig's: median errors $\mu a$ "
        + _pct(b["mu_a"])
        + r", $e_0 a^2$ "
        + _pct(b["e0_a2"])
        + "."
    )


def _coverage_text(c: dict) -> str:
    """The compound benchmark's interval coverage (intervals with the model-form term), when scored."""
    cov, hw = c.get("perturbation_only_interval_coverage"), c.get("perturbation_only_median_interval_halfwidth")
    if not cov or not hw or any(cov.get(k) is None for k in ("mu", "kappa", "e0")):
        return ""
    symbols = (("mu", r"$\mu$"), ("kappa", r"$\kappa$"), ("e0", "$e_0$"), ("mu_a", r"$\mu a$"), ("e0_a2", "$e_0 a^2$"))
    shown = [(k, sym) for k, sym in symbols if cov.get(k) is not None and hw.get(k) is not None]
    return (
        r" The 95\,\% intervals with the model-form term (spread over load cases and over the structures "
        r"the random test allows) held the truth in: "
        + ", ".join(f"{sym} {_pct(cov[k])}" for k, sym in shown)
        + r" of these sets, with median half-widths "
        + ", ".join(sym + r" $\pm$\," + _pct(hw[k]) for k, sym in shown)
        + "."
    )


def _num(x) -> float:
    """A diagnosis.json number (null where it was not finite) as a float."""
    return float("nan") if x is None else float(x)


def _pct(x) -> str:
    return "--" if x is None else f"${_fmt(100 * float(x), 3)}$\\,\\%"


def _law_note(step: dict) -> str:
    """For a contact-separation step whose law never opens the contact: what it stands for instead."""
    if never_opens(step):
        return (
            r" (its law never opens the contact here: it stands for a stiffer or harder normal law than "
            r"Eq.~13's spring, model form rather than separation)"
        )
    return ""


def _periodicity_note(step: dict, periodicity: dict) -> str:
    """For a step whose model settles unlike the records (``settles_unlike_records``): where, and which way."""
    unlike = step.get("settles_unlike_records") or []
    if not unlike:
        return ""
    by = step.get("aperiodic_by_case") or {}
    settled = [c for c in unlike if (periodicity.get(c) or {}).get("settled", True)]
    moving = [c for c in unlike if c not in settled]
    parts = []
    if settled:
        parts.append(
            r"its model does not settle on "
            + ", ".join(_t(c) + " (" + _pct(by.get(c)) + " not periodic)" for c in settled)
            + r", where the record does"
        )
    if moving:
        parts.append(r"its model settles on " + ", ".join(_t(c) for c in moving) + r", where the record does not")
    return r" (" + "; ".join(parts) + r": the law is wrong in form there, whatever its harmonic gap)"


def _updating_note(step: dict, diag: dict) -> str:
    """Why a model update was accepted, when the dual-sine records accepted it (the random test alone did not; records
    that drift are compared with the drift refitted, ``evidence.records_test_of_update``)."""
    upd = (diag.get("where") or {}).get("model_updating") or {}
    if step.get("effect") != "model_updating" or upd.get("accepted_by") != "records":
        return ""
    return (
        r" (not significant on the random test alone, $\chi^2$ "
        + _fmt(upd.get("chi2_nominal", float("nan")), 3)
        + r" $\to$ "
        + _fmt(upd.get("chi2_updated", float("nan")), 3)
        + r"; accepted because it shrinks the held-out gap of the dual-sine records materially"
        + (
            r", compared on what their preload drift leaves, the drift refitted on each model)"
            if "preload_drift" in (upd.get("records_test") or {})
            else r")"
        )
    )


def _alternatives_note(step: dict) -> str:
    """The step's alternatives in words: the candidates the records cannot tell from its effect."""
    alt = step.get("alternatives") or []
    if not alt:
        return ""
    return r" (or, as well within gap.separation on these records, " + " or ".join(_t(a) for a in alt) + ")"


def _kind_note(step: dict) -> str:
    """A step that is not an effect, said: model form (a form candidate the library leaves out, a separation law that
    never opened) or an update that names no effect (story.tell's kinds)."""
    return {"model_form": r" (model form, not an effect)", "update": ""}.get(step.get("kind", "effect"), "")


def explanation_text(diag: dict) -> str:
    """The additive explanation in words (Fig. gap_explanation)."""
    steps, left = diag.get("explanation") or [], diag.get("remaining_gap") or {}
    ended = next(
        (t for t in diag.get("trace") or [] if not t["passed"] and t["test"] not in ("records_agree", "held_out")), None
    )
    if not steps and ended is not None and not ended.get("step"):
        text = r"Nothing is added to the identified model: " + _t(ended["says"]) + ". "
    elif not steps and ended is not None and ended["test"] != "explains_materially":
        text = (
            r"The explanation's first step, "
            + _t(ended["step"])
            + r", is not kept ("
            + _t(ended["test"])
            + r": "
            + _t(ended["says"])
            + r"), so nothing is added to the identified model. "
        )
    elif not steps:
        text = (
            r"No candidate shrinks the held-out gap materially (by gap.min\_reduction $="
            + _fmt(left.get("min_reduction", float("nan")), 2)
            + r"$ of what lies above the floor, gap.min\_gap "
            + _pct(left.get("floor"))
            + r"; by a factor of gap.separation; beyond the records' scatter), so "
            r"nothing is added to the identified model. "
        )
    else:
        periodicity = (diag.get("where") or {}).get("periodicity") or {}
        parts = [
            _t(s["effect"])
            + _kind_note(s)
            + _alternatives_note(s)
            + _updating_note(s, diag)
            + _law_note(s)
            + _periodicity_note(s, periodicity)
            + (r" (held where the random test measured it, not refitted: " if s.get("held") else r" (refitted: ")
            + ", ".join(f"{_t(k)} $= {_fmt(v, 3)}$" for k, v in s["parameters"].items())
            + r") takes the held-out gap from "
            + _pct(s["heldout_gap_before"])
            + " to "
            + _pct(s["heldout_gap_after"])
            + r" ("
            + _pct(s["share"])
            + r" of its power)"
            for s in steps
        ]
        text = r"Added one after the other, each refitted on top of the ones before: " + "; then ".join(parts) + ". "
    if left:
        text += (
            r"What remains is "
            + _pct(left["heldout_gap"])
            + r" ("
            + _pct(left["share"])
            + r" of the power), "
            + (
                r"at the identification's own floor (gap.min\_gap " + _pct(left["floor"]) + ")"
                if left["at_floor"]
                else r"in \emph{" + _t(left["place"]) + r"} (" + _t(left["place_reason"]) + ")"
            )
            + r"; Fig.~\ref{fig:gap_explanation}."
        )
    return text + measured_floor_text(diag)


def measured_floor_text(diag: dict) -> str:
    """Where gap.min_gap is measured (gap.measure_floor, ``gap.floor``): what the rig without effects left at the
    records' drive."""
    m = diag.get("measured_floor")
    if not m:
        return ""
    if m.get("floor") is None:
        left = diag.get("remaining_gap") or {}
        return (
            r" The floor was not measured for these records ("
            + _t(str(m.get("reason", "")))
            + r"): gap.min\_gap is the configured "
            + _pct(left.get("floor"))
            + "."
        )
    return (
        r" The floor gap.min\_gap is measured for these records (gap.measure\_floor): the rig without effects, the "
        r"identified friction law as its truth, driven at $"
        + _fmt(m["drive_hz"], 4)
        + r"$~Hz and identified by the chain, leaves a held-out gap of "
        + _pct(m["floor"])
        + r"; gap.min\_gap is $"
        + _fmt(m["factor"], 2)
        + r"$ times it."
    )


def updated_law_note(intervals: dict | None) -> str:
    """A sentence for Table 4's caption where the random test's model updating changed the structure
    (friction_intervals.json's model "updated"): Table 4's law rests on the nominal structure, and the updated model's
    law, with its model-form intervals (``intervals_text``'s table), is the one to read; "" otherwise. (A structure 12 %
    softer with accelerometers 60 % heavy: Table 4 gave mu 0.277 with an interval 0.224-0.324 that excludes the rig's
    0.397; the updated model 0.388, 0.312-0.482.)"""
    if not intervals or intervals.get("model") != "updated":
        return ""
    par = intervals.get("parameters") or {}
    symbols = {"mu": r"\mu", "kappa": r"\kappa", "e0": r"e_0(N_0)"}
    parts = [
        f"${sym} = {_fmt(par[n]['value'], 3)}$ (${_fmt(par[n]['interval'][0], 3)}$--${_fmt(par[n]['interval'][1], 3)}$)"
        for n, sym in symbols.items()
        if n in par
    ]
    return (
        " These rest on the nominal structure, which the random test's model updating changed; the updated model's "
        "law, with the model-form term (Table~\\ref{tab:intervals}), gives " + ", ".join(parts) + "."
    )


def explained_law_note(updated: dict | None) -> str:
    """A sentence for Table 4's caption where the gap diagnosis explained effects, or applied the damping at test level
    the records confirm (results/gap/updated_model.json): the friction law refitted with them beside the chain's,
    which they bias; "" where the model is the chain's."""
    if not updated:
        return ""
    td = updated.get("damping_at_test_level") or {}
    if updated.get("effects"):
        what = "Refitted with the effects the gap diagnosis explains (" + ", ".join(_t(n) for n in updated["effects"])
        tail = "the chain's law above carries what those effects do to the identified S."
    elif td.get("applied"):
        which = f"mode {td['driven_mode']}'s damping ratio" if td["form"] == "driven" else "every mode's damping ratio"
        scale = _fmt(td["scale"], 3)
        what = f"With {which} at test level, ${scale}$ times the random test's, as the other load cases confirm"
        tail = "the chain's law above carries the damping the random test misstates."
    else:
        return ""
    fr = updated["friction"]
    return (
        " "
        + what
        + r"; results/gap/updated\_model.json), the law is $\mu = "
        + _fmt(fr["mu"], 3)
        + r"$, $\kappa = "
        + _fmt(fr["kappa"], 3)
        + r"$, $e_0(N_0) = "
        + _fmt(fr["e0_at_preload"], 3)
        + "$~N/m: "
        + tail
    )


def intervals_text(intervals: dict | None) -> str:
    """The friction law's intervals with the model-form term (friction_intervals.json) as a paragraph and table."""
    if not intervals:
        return ""
    par = intervals["parameters"]
    names = {
        "e_f": "e_f (N/m)",
        "k_c": "k_c (1/m)",
        "e_t": "e_t (N/m)",
        "kappa": "kappa",
        "mu": "mu",
        "e0": "e_0 at N_0 (N/m)",
        "mu_a": "mu a (m)",
        "e0_a2": "e_0 a^2 (N m)",
    }
    rows = pd.DataFrame(
        [
            {
                "p": names[n],
                "value": v["value"],
                "plo": v["profile_interval"][0],
                "phi": v["profile_interval"][1],
                "sdc": v["sd_cases"],
                "sds": v["sd_structure"],
                "lo": v["interval"][0],
                "hi": v["interval"][1],
            }
            for n, v in par.items()
            if n in names
        ]
    )
    text = (
        r"\paragraph{Friction law with model-form uncertainty.} The profile-likelihood intervals hold if the model "
        r"is right. The law of the " + _t(intervals["model"]) + r" model was refitted on each other load case and "
        r"on the calibration forces identified with each of the " + str(intervals["n_structures"]) + r" structures "
        r"the random test allows ($\pm$1 posterior standard deviation along each principal axis of the model "
        r"updating); their spreads (sd, on a log scale for the positive parameters) widen the intervals. The "
        r"tangential lever arm, which the linear data do not bound, sets most of the structural term of $\mu$ and "
        r"$e_0$: the data bind $\mu a$ and $e_0 a^2$, whose intervals (the last rows, each refit times its own "
        r"lever arm) stay narrow where those of $\mu$ and $e_0$ open with $a$."
    )
    return (
        text
        + "\n"
        + tabular(
            rows,
            {
                "p": "parameter",
                "value": "value",
                "plo": "profile low",
                "phi": "profile high",
                "sdc": "sd cases",
                "sds": "sd structure",
                "lo": "low",
                "hi": "high",
            },
            "Friction law: profile-likelihood interval and the 95\\,\\% interval with the "
            "model-form term (spreads over load cases and structures); each value printed to the digits that "
            "interval supports.",
            "tab:intervals",
            intervals={"value": ("lo", "hi")},
        )
    )


def comparison_lines(diag: dict) -> list[str]:
    """The section's opening lines: what is compared with what, and the calibration case."""
    return [
        r"The identified model (linear stiffnesses and damping of the linear chain, the fitted friction law, the",
        r"linear normal spring of Eq.~13) is simulated under each load case's measured force and compared with the",
        r"records at every level of the chain. The friction law was fitted on "
        + _t(diag["calibration_case"])
        + (
            r"; the other load cases are held out."
            if diag.get("heldout_cases")
            else r", the only load case: no case is held out, and every gap below is the calibration case's own."
        ),
    ]


def periodicity_text(w: dict) -> str:
    """Whether each record settled (``where.periodicity``): one sentence, empty where the diagnosis has none."""
    per = w.get("periodicity") or {}
    if not per:
        return ""
    unsettled = {c: p for c, p in per.items() if not p.get("settled", True)}
    if not unsettled:
        worst = max(_num(p["aperiodic_share"]) for p in per.values())
        return (
            r" Every record settled: at most "
            + _pct(worst)
            + r" of an accelerometer's response is not periodic at the drive frequency (a settled response leaves "
            r"its noise alone)."
        )
    parts = []
    for c, p in unsettled.items():
        by = p.get("by_sensor") or {}
        sensor = max(by, key=lambda k: _num(by[k])) if by else None
        parts.append(_t(c) + " (" + _pct(p["aperiodic_share"]) + (" at " + _t(sensor) if sensor else "") + ")")
    return (
        " "
        + ", ".join(parts)
        + r" did not settle: that share of the response is not periodic at the drive frequency (impacts, a motion "
        r"that never repeats, or a test that drifts). "
        + (
            r"The records drift (the place is non\_stationary): a drift alone leaves a record that much "
            r"from periodic."
            if w.get("place") == "non_stationary"
            else ("Their" if len(parts) > 1 else "Its")
            + r" harmonics are averages of that motion, and no candidate compared on harmonics can be expected to "
            r"explain a gap there."
        )
    )


def where_paragraph(diag: dict) -> str:
    """The paragraph 'Where the gap lies': the held-out gap (%), by stage, the worst sensor, harmonic and part of
    the cycle, and the place the localisation names."""
    w = diag["where"]
    st = w["stage"]
    return (
        r"\paragraph{Where the gap lies.} Held-out gap (sensor harmonics 1--"
        + str(len(w["by_harmonic"]))
        + r"): "
        + _pct(w["heldout_gap_before"])
        + r" (bootstrap 95\,\% "
        + _pct(w["heldout_gap_before_interval"][0])
        + "--"
        + _pct(w["heldout_gap_before_interval"][1])
        + r"; the records' own scatter "
        + _pct(w["record_scatter"])
        + "). "
        r"By stage: accelerations "
        + _pct(st["accelerations"])
        + r", generalized coordinates "
        + _pct(st["generalized_coordinates"])
        + r", inverse-identification sensor misfit "
        + _pct(st.get("identification_residual"))
        + r", friction law against identified $S$ "
        + _pct(st["contact_force_S"])
        + r", best elastic normal law against identified $N$ "
        + _pct(st["contact_force_N"])
        + r", dissipated energy per cycle "
        r"(tangential) "
        + _pct(st["energy_tangential"])
        + r", random-test FRF peaks "
        + _pct(st.get("frf_peak_amplitude"))
        + r". Worst sensor "
        + _t(w["worst_sensor"])
        + r", worst harmonic "
        + str(w["worst_harmonic"])
        + r" (even harmonics carry "
        + _pct(w["even_share"])
        + r" of the residual), worst part of the cycle: "
        + _t(w["worst_cycle_part"])
        + r"."
        + periodicity_text(w)
        + r" "
        r"The localisation places the gap in: \emph{" + _t(w["place"]) + r"} (" + _t(w["place_reason"]) + r"); "
        r"Fig.~\ref{fig:gap_stages}."
    )


def _factor_list(factors: dict) -> str:
    return ", ".join(_t(k) + r" $\times" + _fmt(float(v), 4) + "$" for k, v in factors.items())


def _records_verdict(rt: dict | None) -> str:
    """The dual-sine records' test of an update (``records_test``) in words, or "" where it was not run."""
    if not rt:
        return ""
    return (
        r"held-out gap "
        + _pct(rt.get("heldout_gap_chain"))
        + r" with the nominal structure, "
        + _pct(rt.get("heldout_gap_updated"))
        + r" with the update, the records' scatter "
        + _pct(rt.get("record_scatter"))
        + (r", the preload drift refitted on each model" if "preload_drift" in rt else "")
    )


def _why_not(rt: dict, floor) -> str:
    """Why the dual-sine records did not accept an update: nothing above the floor to explain, or too little
    explained (``verdict.records_accept_update``)."""
    gap = rt.get("heldout_gap_chain")
    if gap is not None and floor is not None and at_floor(float(gap), {"min_gap": float(floor)}):
        return r": the nominal structure's gap lies at the identification's floor, gap.min\_gap " + _pct(floor)
    return r": the update does not shrink it by gap.min\_reduction beyond the records' scatter"


def _identifiability_text(ident: dict) -> str:
    """What the random test binds (each factor's posterior sd, on its log: relative) and what it leaves at its prior."""
    factors = {k: v for k, v in ident.items() if k not in ("k_t", "k_n") and isinstance(v, dict)}
    bound = [(k, v) for k, v in factors.items() if v.get("bound_by_data")]
    free = [k for k, v in factors.items() if not v.get("bound_by_data")]
    text = ""
    if bound:
        text += (
            r" The random test binds "
            + ", ".join(_t(k) + r" ($\pm$\," + _pct(v.get("posterior_sd")) + ")" for k, v in bound)
            + "."
        )
    if free:
        text += (
            r" It leaves "
            + ", ".join(_t(k) for k in free)
            + r" near "
            + ("its" if len(free) == 1 else "their")
            + r" prior (posterior sd above half the prior's): what the model assumes there, the data do not check."
        )
    return text


def _channel_gains_text(upd: dict) -> str:
    """The accelerometer channels' sensitivities relative to one another (the random test's residues) in words."""
    gains, sd = upd.get("channel_gains") or [], upd.get("channel_gain_sd") or []
    if not gains:
        return ""
    if upd.get("channel_gains_significant"):
        significance = r"; they lower the nominal structure's $\chi^2$ significantly and are fitted with the update"
    elif upd.get("gains_versus_structure"):
        significance = r"; they lower the nominal structure's $\chi^2$ significantly"
    else:
        significance = r"; within their scatter, so the update is fitted without them"
    return (
        r" The accelerometer channels' gains relative to one another (their logarithms sum to zero), read off the "
        r"random test's residues: "
        + ", ".join(
            f"channel {i + 1} ${_fmt(float(g), 4)}$" + (r" ($\pm$\," + _pct(s) + ")" if s is not None else "")
            for i, (g, s) in enumerate(zip(gains, list(sd) + [None] * (len(gains) - len(sd))))
        )
        + significance
        + r". "
        + _gains_versus_structure_text(upd.get("gains_versus_structure"))
        + r"The channel-gain candidate applies them as they are."
    )


def _gains_versus_structure_text(test: dict | None) -> str:
    """Where the random test could not tell the channels' gains from the structure's factors: what the dual-sine
    records chose (``evidence.records_test_of_gains``)."""
    if not test:
        return ""
    return (
        r"But the structure's factors alone fit the random test as well ($\chi^2$ lower by "
        + _fmt(_num(test.get("gains_drop")), 3)
        + r" with the gains, "
        + _fmt(_num(test.get("gains_threshold")), 3)
        + r" needed), so the dual-sine records chose: held-out gap "
        + _pct(test.get("heldout_gap_gains"))
        + r" with the update read through the gains, "
        + _pct(test.get("heldout_gap_structure"))
        + r" with the structure alone (the records' scatter "
        + _pct(test.get("record_scatter"))
        + r"); the update is made "
        + (r"with the gains. " if test.get("gains_preferred") else r"without them. ")
    )


def updating_paragraph(diag: dict) -> str:
    """The paragraph 'The base model': the structure updated from the random test (chi^2 before and after against
    its bar, accepted or not and by what, what the data bind, the channels' relative gains); "" without an update."""
    upd = (diag.get("where") or {}).get("model_updating")
    if not upd:
        return ""
    chi2 = (
        r"$\chi^2$ "
        + _fmt(_num(upd.get("chi2_nominal")), 3)
        + r" for the nominal structure, "
        + _fmt(_num(upd.get("chi2_updated")), 3)
        + r" for the best update ("
        + str(upd.get("n_data", "--"))
        + r" data); "
        + (
            r"a drop of "
            + _fmt(_num(upd.get("chi2_threshold")), 3)
            + r" is significant for the "
            + _fmt(_num(upd.get("effective_factors")), 2)
            + r" factors the data bind"
            if upd.get("chi2_threshold") is not None
            else r"no drop is significant"
        )
    )
    by, records = upd.get("accepted_by") or ("random_test" if upd.get("accepted") else ""), upd.get("records_test")
    if upd.get("accepted") and by == "records":
        outcome = (
            r" Not significant on the random test alone; the dual-sine records accepted it ("
            + _records_verdict(records)
            + r"): the updated structure ("
            + _factor_list(upd.get("factors") or {})
            + r") feeds the identification and the friction fit."
        )
    elif upd.get("accepted"):
        outcome = (
            r" The drop is significant: the updated structure ("
            + _factor_list(upd.get("factors") or {})
            + r") feeds the identification and the friction fit."
        )
    else:
        prop = (upd.get("proposal") or {}).get("factors") or {}
        outcome = (
            r" Not significant, so the nominal structure is kept"
            + (r" (the update proposed " + _factor_list(prop) + ")" if prop else "")
            + (
                r"; nor did the dual-sine records accept it ("
                + _records_verdict(records)
                + _why_not(records, (diag.get("remaining_gap") or {}).get("floor"))
                + ")"
                if records
                else ""
            )
            + "."
        )
    return (
        r"\paragraph{The base model.} Before any contact effect is tried, the structure is updated from the random "
        r"test (its natural frequencies and the residues at the sensors): "
        + chi2
        + "."
        + outcome
        + _identifiability_text(upd.get("identifiability") or {})
        + _channel_gains_text(upd)
    )


def damping_at_test_level_text(diag: dict) -> str:
    """What became of the damping at test level (diagnosis.json's ``damping_at_test_level``, rule test_damping): the
    factor the calibration record binds, the other load cases' test and whether the diagnosed model carries it; ""
    where the law misfits least at the random test's ratios."""
    td = diag.get("damping_at_test_level") or {}
    if not td or abs(float(td.get("scale", 1.0)) - 1.0) < 1e-9:
        return ""
    which = f"mode {td['driven_mode']}'s damping ratio" if td["form"] == "driven" else "every mode's damping ratio"
    text = (
        r"\paragraph{Damping at test level.} The friction law misfits the calibration record least with "
        + f"{which} ${_fmt(td['scale'], 3)}$ times the random test's"
    )
    if "heldout_gap_test_damping" in td:
        text += (
            f"; on the other load cases the held-out gap is {_pct(td['heldout_gap_random_test_damping'])} with the "
            f"random test's ratios and {_pct(td['heldout_gap_test_damping'])} with the factor"
        )
    if td.get("applied"):
        return text + (
            r". Confirmed, and with no effect explained, the model the diagnosis arrives at carries it with the law "
            r"fitted with it (results/gap/updated\_model.json, Table 4's caption)."
        )
    return text + ". Not applied: " + _t(td.get("why", "")) + "."


def diagnosis_paragraphs(diag: dict) -> str:
    """The diagnosis in words (newline-terminated lines): the comparison, where the gap lies, the base model's update
    from the random test, which effect, and the additive explanation step by step."""
    base = updating_paragraph(diag)
    lines = [
        *comparison_lines(diag),
        "",
        where_paragraph(diag),
        "",
        *([base, ""] if base else []),
        r"\paragraph{Which effect.} Verdict: \textbf{" + _t(diag["verdict"]) + r"} --- " + _t(diag["reason"]) + ".",
        "",
        *([resolution_text(diag), ""] if diag.get("resolution") else []),
        *([damping_at_test_level_text(diag), ""] if damping_at_test_level_text(diag) else []),
        *([trace_text(diag), ""] if diag.get("trace") else []),
        r"\paragraph{Step by step.} " + explanation_text(diag),
        "",
    ]
    return "\n".join(lines) + "\n"


def resolution_text(diag: dict) -> str:
    """What these records can attribute to an effect (diagnosis.json's resolution), in words."""
    r = diag["resolution"]
    iso = r.get("isolability") or {}
    pairs = iso.get("pairs") or []
    text = r"\paragraph{Resolution.} " + _t(r["how"]) + ". "
    if pairs:
        text += (
            r"These records cannot tell apart (their signatures on the held-out records, with what "
            + (" and ".join(_t(f) for f in iso.get("form_removed") or []) or "the base model's form")
            + r" absorbs removed, point the same way, cosine above $"
            + _fmt(iso.get("limit", float("nan")), 2)
            + r"$): "
            + "; ".join(
                " and ".join(_t(c) for c in p["candidates"]) + r" ($" + _fmt(p["cosine"], 3) + r"$)" for p in pairs
            )
            + "."
        )
    elif iso:
        text += r"Every pair of candidates changes the held-out records in its own way (isolability table empty)."
    return text


def _trace_value(v) -> str:
    if isinstance(v, bool) or v is None:
        return _t(str(v))
    if isinstance(v, (int, float)):
        return "$" + _fmt(v, 3) + "$"
    return _t(str(v))


def trace_text(diag: dict) -> str:
    """The decisions the verdict was told by, in order (diagnosis.json's trace): test, the step it judged, value
    against threshold, passed or not."""
    items = [
        _t(t["test"])
        + (r" (" + _t(t["step"]) + ")" if t.get("step") else "")
        + ": "
        + _trace_value(t["value"])
        + r" against "
        + _trace_value(t["threshold"])
        + (r", passed" if t["passed"] else r", \textbf{not passed}")
        for t in diag["trace"]
    ]
    return r"\paragraph{Decisions, in order.} " + "; ".join(items) + "."


def candidates_table(diag: dict) -> str:
    """The table of the candidates (held-out gap before and after, its bootstrap interval and the shrink in %, the
    score); empty without candidates."""
    rows = pd.DataFrame(
        [
            {
                "effect": r["effect"] + ("*" if r.get("settles_unlike_records") else ""),
                "k": r["n_parameters"],
                "before": 100 * _num(r["heldout_gap_before"]),
                "after": 100 * _num(r["heldout_gap_after"]),
                "low": 100 * _num(r["heldout_gap_after_interval"][0]),
                "high": 100 * _num(r["heldout_gap_after_interval"][1]),
                "reduction": 100 * _num(r["reduction"]),
                "score": _num(r["score"]),
            }
            for r in diag["ranking"]
        ]
    )
    if not len(rows):
        return ""
    return tabular(
        rows,
        {
            "effect": "candidate",
            "k": "$k$",
            "before": "before (\\%)",
            "after": "after (\\%)",
            "low": "2.5\\,\\%",
            "high": "97.5\\,\\%",
            "reduction": "shrink (\\%)",
            "score": "score",
        },
        "Candidate effects refitted on the calibration case and scored on the held-out cases "
        "(held-out gap before and after, bootstrap interval of after, score $n\\ln(g_a^2/g_b^2)+2k$)."
        + (
            " *: its model does not settle on a record that did, or settles on one that did not (the law is wrong in "
            "form there, whatever its harmonic gap)."
            if any(r.get("settles_unlike_records") for r in diag["ranking"])
            else ""
        ),
        "tab:gap",
    )


def _figure(name: str, caption: str) -> str:
    """A gap figure at the report's text width, the width it is drawn at (print_style): text >= 8 pt on paper."""
    return (
        "\\begin{figure}[H]\\centering\\includegraphics[width=\\textwidth]{" + name + ".pdf}"
        "\\caption{" + caption + "}\\label{fig:" + name + "}\\end{figure}\n"
    )


# the diagnosis' figures the report includes (results/gap/*.pdf); the diagnostic views stay in results/gap/
GAP_FIGURES = (
    _figure(
        "gap_stages",
        "The gap at each stage of the chain, identified model against the records (log axis; a zero value is "
        "written as 0), and the threshold each value is compared with: gap.min\\_gap for the held-out gap, the "
        "localisation's (gap.place) for the identification misfit and the normal law.",
    )
    + _figure(
        "gap_ranking",
        "The candidates ranked: held-out gap with each candidate added (95\\,\\% bootstrap interval) against the "
        "gap before, the identification's floor gap.min\\_gap (below it the verdict is none) and the records' "
        "scatter. A candidate that does not lower the gap ends at `before', marked no effect.",
    )
    + _figure(
        "gap_shrink",
        "Held-out gap before and after the winner and the runner-up, per held-out load case (95\\,\\% bootstrap "
        "intervals) and per harmonic.",
    )
    + _figure(
        "gap_explanation",
        "The held-out gap explained step by step: the identified model, what each added effect removes, what "
        "remains (dotted: the identification's floor gap.min\\_gap).",
    )
    + "The diagnostic views are figures of their own in \\texttt{results/gap/}: the gap by harmonic and by sensor "
    "(\\texttt{gap\\_harmonics.png}), by part of the cycle with the dissipation in each direction "
    "(\\texttt{gap\\_cycle.png}) and the residual force-state maps (\\texttt{gap\\_force\\_state.png}).\n"
)

NO_BENCHMARK = (
    "\n\\paragraph{Blind benchmark.} Not built with this report (\\texttt{gap\\_benchmark.in\\_report: "
    "false}); run \\texttt{snakemake gap\\_benchmark}.\n"
)


def blind_paragraph(bench: dict) -> str:
    """The blind benchmark in words: top-1 accuracy, false alarms, shrink of the correctly named effects (%), the
    left-out items and the median diagnosis time (s)."""
    lo = bench["leave_out"]
    return (
        "\n\\paragraph{Blind benchmark.} " + str(bench["n_blind"]) + r" rig data sets, each with one effect on at a "
        r"random (seeded) magnitude, diagnosed from their raw records alone: top-1 accuracy "
        + _pct(bench["top1_accuracy"])
        + r"; false alarms on effect-free data: "
        + str(bench["false_alarms"])
        + " of "
        + str(bench["n_effect_free"])
        + r"; held-out gap shrink of the correctly named effects: smallest "
        + _pct(bench["shrink_of_correct"]["min"])
        + r", median "
        + _pct(bench["shrink_of_correct"]["median"])
        + r". With the effect left out of the library ("
        + str(lo["n"])
        + r" data sets) the verdict was ``none'' in "
        + str(lo["verdict_none"])
        + r" and the localisation named the right place in "
        + str(lo["place_right"])
        + r". Diagnosis time per data set (three load cases): median "
        + f"${bench['diagnosis_seconds']['median']:.0f}$"
        + "\\,s.\n"
    )


def compound_paragraph(c: dict) -> str:
    """The compound benchmark in words: effects named (%), the remaining held-out gap and the friction law's errors
    after updating (%), with what the data bind and the intervals' coverage when scored."""
    err = c["perturbation_only_median_abs_error"]
    return (
        "\n\\paragraph{Compound benchmark.} " + str(c["n"]) + r" rig data sets whose structure (E, transducer "
        r"masses, tangential lever arm; on half of them a clamp that gives), normal law and damping form differ "
        r"from the model's at random, with 0, 1 or 2 effects ("
        + ", ".join(f"{v} with {k}" for k, v in c["n_by_effect_count"].items())
        + r"), diagnosed "
        r"with model updating and scored on the additive explanation. Perturbation only: no contact effect named "
        r"in "
        + _pct(c["perturbation_only_no_contact_effect"])
        + r"; one effect: named in "
        + _pct(c["one_effect_named"])
        + r", no absent contact effect in "
        + _pct(c["one_effect_no_absent_contact_effect"])
        + r"; two effects: both named in "
        + _pct(c["two_effects_both_named"])
        + r", at least one in "
        + _pct(c["two_effects_one_named"])
        + r". Median remaining held-out gap "
        + _pct(c["remaining_gap_median"])
        + r". Perturbation only, after updating, median errors: $\mu$ "
        + _pct(err["mu"])
        + r", $\kappa$ "
        + _pct(err["kappa"])
        + r", $e_0$ "
        + _pct(err["e0"])
        + r" (the tangential lever arm, which linear data do not "
        r"bound, scales the identified $S$ and so $\mu$)." + _bound_text(c) + _coverage_text(c)
    ) + "\n"


def accuracy_table(bench: dict) -> str:
    """The blind benchmark's top-1 accuracy per effect (%) as a table, and the confusion matrix's figure."""
    acc = pd.DataFrame([{"effect": e, "accuracy": 100 * a} for e, a in bench["per_effect_accuracy"].items()])
    return tabular(
        acc, {"effect": "effect", "accuracy": "top-1 (\\%)"}, "Blind benchmark: accuracy per effect.", "tab:bench"
    ) + (
        "\\begin{figure}[H]\\centering\\includegraphics[width=0.6\\textwidth]{confusion.png}"
        "\\caption{Blind benchmark: confusion matrix.}\\label{fig:confusion}\\end{figure}\n"
    )


def benchmark_text(bench: dict | None) -> str:
    """The benchmarks' part of the section: the blind benchmark, the compound one when built, the accuracy table;
    a note when the benchmark was not built (``bench`` None)."""
    if bench is None:
        return NO_BENCHMARK
    out = blind_paragraph(bench)
    c = bench.get("compound")
    if c:
        out += compound_paragraph(c)
    return out + accuracy_table(bench)


def gap_section(diag: dict, bench: dict | None, intervals: dict | None = None) -> str:
    """The report's section on the gap (LaTeX) from diagnosis.json, benchmark.json (None: not built) and
    friction_intervals.json (None: left out)."""
    return (
        diagnosis_paragraphs(diag)
        + candidates_table(diag)
        + GAP_FIGURES
        + intervals_text(intervals)
        + benchmark_text(bench)
    )
