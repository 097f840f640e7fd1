"""The gap section's diagnosis in words (text generated from diagnosis.json).

The comparison, where the gap lies, which effect, the resolution, the damping at test level, the decisions in order
and the additive explanation step by step with the measured floor; the base model's paragraph is
``report_base_model``'s.
"""

from __future__ import annotations

from ..latex import latex_number
from ..latex import plain_text as _t
from ..test_damping import ratio_words
from .place import never_opens
from .report_base_model import updating_paragraph
from .report_format import num, pct


def _law_note(step: dict) -> str:
    """Return, for a contact-separation step whose law never opens the contact, what it stands for instead."""
    if never_opens(step):
        return (
            r" (its law never opens the contact here: it stands for a stiffer or harder normal law than "
            r"Eq.~13's spring, model form rather than separation)"
        )
    return ""


def _periodicity_note(step: dict, periodicity: dict) -> str:
    """Return, for a step whose model settles unlike the records (``settles_unlike_records``), where and which way."""
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
            + ", ".join(_t(c) + " (" + pct(by.get(c)) + " not periodic)" for c in settled)
            + r", where the record does"
        )
    if moving:
        parts.append(r"its model settles on " + ", ".join(_t(c) for c in moving) + r", where the record does not")
    return r" (" + "; ".join(parts) + r": the law is wrong in form there, whatever its harmonic gap)"


def _updating_note(step: dict, diag: dict) -> str:
    """Return why a model update was accepted, when the dual-sine records accepted it.

    The random test alone did not; records that drift are compared with the drift refitted
    (``evidence.records_test_of_update``).
    """
    upd = (diag.get("where") or {}).get("model_updating") or {}
    if step.get("effect") != "model_updating" or upd.get("accepted_by") != "records":
        return ""
    return (
        r" (not significant on the random test alone, $\chi^2$ "
        + latex_number(upd.get("chi2_nominal", float("nan")), 3)
        + r" $\to$ "
        + latex_number(upd.get("chi2_updated", float("nan")), 3)
        + r"; accepted because it shrinks the held-out gap of the dual-sine records materially"
        + (
            r", compared on what their preload drift leaves, the drift refitted on each model)"
            if "preload_drift" in (upd.get("records_test") or {})
            else r")"
        )
    )


def _alternatives_note(step: dict) -> str:
    """Return the step's alternatives in words: the candidates the records cannot tell from its effect."""
    alt = step.get("alternatives") or []
    if not alt:
        return ""
    return r" (or, as well within gap.separation on these records, " + " or ".join(_t(a) for a in alt) + ")"


def _kind_note(step: dict) -> str:
    """Return what a step that is not an effect is, in words.

    Model form (a form candidate the library leaves out, a separation law that never opened) or an update that names
    no effect (story.tell's kinds).
    """
    return {"model_form": r" (model form, not an effect)", "update": ""}.get(step.get("kind", "effect"), "")


def explanation_text(diag: dict) -> str:
    """Return the additive explanation in words (Fig. gap_explanation).

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``explanation``, ``remaining_gap``, ``trace``,
        ``where`` (``periodicity``, ``model_updating``) and ``measured_floor`` are read.

    Returns
    -------
    text : str
        The explanation step by step, what remains and the measured floor, in LaTeX.
    """
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
            + latex_number(left.get("min_reduction", float("nan")), 2)
            + r"$ of what lies above the floor, gap.min\_gap "
            + pct(left.get("floor"))
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
            + ", ".join(f"{_t(k)} $= {latex_number(v, 3)}$" for k, v in s["parameters"].items())
            + r") takes the held-out gap from "
            + pct(s["heldout_gap_before"])
            + " to "
            + pct(s["heldout_gap_after"])
            + r" ("
            + pct(s["share"])
            + r" of its power)"
            for s in steps
        ]
        text = r"Added one after the other, each refitted on top of the ones before: " + "; then ".join(parts) + ". "
    if left:
        text += (
            r"What remains is "
            + pct(left["heldout_gap"])
            + r" ("
            + pct(left["share"])
            + r" of the power), "
            + (
                r"at the identification's own floor (gap.min\_gap " + pct(left["floor"]) + ")"
                if left["at_floor"]
                else r"in \emph{" + _t(left["place"]) + r"} (" + _t(left["place_reason"]) + ")"
            )
            + r"; Fig.~\ref{fig:gap_explanation}."
        )
    return text + measured_floor_text(diag)


def measured_floor_text(diag: dict) -> str:
    """Return where gap.min_gap is measured (gap.measure_floor, ``gap.floor``), in words.

    What the rig without effects left at the records' drive.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``measured_floor`` and ``remaining_gap.floor`` are read.

    Returns
    -------
    text : str
        One or two sentences in LaTeX; "" where the diagnosis has no measured floor.
    """
    m = diag.get("measured_floor")
    if not m:
        return ""
    if m.get("floor") is None:
        left = diag.get("remaining_gap") or {}
        return (
            r" The floor was not measured for these records ("
            + _t(str(m.get("reason", "")))
            + r"): gap.min\_gap is the configured "
            + pct(left.get("floor"))
            + "."
        )
    return (
        r" The floor gap.min\_gap is measured for these records (gap.measure\_floor): the rig without effects, the "
        r"identified friction law as its truth, driven at $"
        + latex_number(m["drive_hz"], 4)
        + r"$~Hz and identified by the chain, leaves a held-out gap of "
        + pct(m["floor"])
        + r"; gap.min\_gap is $"
        + latex_number(m["factor"], 2)
        + r"$ times it."
    )


def comparison_lines(diag: dict) -> list[str]:
    """Return the section's opening lines: what is compared with what, and the calibration case.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``calibration_case`` and ``heldout_cases`` are read.

    Returns
    -------
    lines : list[str]
        The lines in LaTeX.
    """
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
    """Return whether each record settled (``where.periodicity``): one sentence, empty where the diagnosis has none.

    Parameters
    ----------
    w
        The diagnosis's ``where`` section: its ``periodicity`` ({case: {settled, aperiodic_share, by_sensor}}) and
        ``place`` are read.

    Returns
    -------
    text : str
        The sentence in LaTeX, with a leading space; "" without periodicity.
    """
    per = w.get("periodicity") or {}
    if not per:
        return ""
    unsettled = {c: p for c, p in per.items() if not p.get("settled", True)}
    if not unsettled:
        worst = max(num(p["aperiodic_share"]) for p in per.values())
        return (
            r" Every record settled: at most "
            + pct(worst)
            + r" of an accelerometer's response is not periodic at the drive frequency (a settled response leaves "
            r"its noise alone)."
        )
    parts = []
    for c, p in unsettled.items():
        by = p.get("by_sensor") or {}
        sensor = max(by, key=lambda k: num(by[k])) if by else None
        parts.append(_t(c) + " (" + pct(p["aperiodic_share"]) + (" at " + _t(sensor) if sensor else "") + ")")
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
    """Return the paragraph 'Where the gap lies'.

    The held-out gap (%), by stage, the worst sensor, harmonic and part of the cycle, and the place the localisation
    names.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``where`` section is read.

    Returns
    -------
    text : str
        The paragraph in LaTeX.
    """
    w = diag["where"]
    st = w["stage"]
    return (
        r"\paragraph{Where the gap lies.} Held-out gap (sensor harmonics 1--"
        + str(len(w["by_harmonic"]))
        + r"): "
        + pct(w["heldout_gap_before"])
        + r" (bootstrap 95\,\% "
        + pct(w["heldout_gap_before_interval"][0])
        + "--"
        + pct(w["heldout_gap_before_interval"][1])
        + r"; the records' own scatter "
        + pct(w["record_scatter"])
        + "). "
        r"By stage: accelerations "
        + pct(st["accelerations"])
        + r", generalized coordinates "
        + pct(st["generalized_coordinates"])
        + r", inverse-identification sensor misfit "
        + pct(st.get("identification_residual"))
        + r", friction law against identified $S$ "
        + pct(st["contact_force_S"])
        + r", best elastic normal law against identified $N$ "
        + pct(st["contact_force_N"])
        + r", dissipated energy per cycle "
        r"(tangential) "
        + pct(st["energy_tangential"])
        + r", random-test FRF peaks "
        + pct(st.get("frf_peak_amplitude"))
        + r". Worst sensor "
        + _t(w["worst_sensor"])
        + r", worst harmonic "
        + str(w["worst_harmonic"])
        + r" (even harmonics carry "
        + pct(w["even_share"])
        + r" of the residual), worst part of the cycle: "
        + _t(w["worst_cycle_part"])
        + r"."
        + periodicity_text(w)
        + r" "
        r"The localisation places the gap in: \emph{" + _t(w["place"]) + r"} (" + _t(w["place_reason"]) + r"); "
        r"Fig.~\ref{fig:gap_stages}."
    )


def damping_at_test_level_text(diag: dict) -> str:
    """Return what became of the damping at test level (diagnosis.json's ``damping_at_test_level``).

    From rule test_damping: the factor the calibration record binds, the other load cases' test and whether the
    diagnosed model carries it.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``damping_at_test_level`` is read.

    Returns
    -------
    text : str
        The paragraph in LaTeX; "" where the law misfits least at the random test's ratios.
    """
    td = diag.get("damping_at_test_level") or {}
    if not td or abs(float(td.get("scale", 1.0)) - 1.0) < 1e-9:
        return ""
    which = ratio_words(td["form"], td["driven_mode"])
    text = (
        r"\paragraph{Damping at test level.} The friction law misfits the calibration record least with "
        + f"{which} ${latex_number(td['scale'], 3)}$ times the random test's"
    )
    if "heldout_gap_test_damping" in td:
        text += (
            f"; on the other load cases the held-out gap is {pct(td['heldout_gap_random_test_damping'])} with the "
            f"random test's ratios and {pct(td['heldout_gap_test_damping'])} with the factor"
        )
    if td.get("applied"):
        return text + (
            r". Confirmed, and with no effect explained, the model the diagnosis arrives at carries it with the law "
            r"fitted with it (results/gap/updated\_model.json, Table 4's caption)."
        )
    return text + ". Not applied: " + _t(td.get("why", "")) + "."


def diagnosis_paragraphs(diag: dict) -> str:
    """Return the diagnosis in words (newline-terminated lines).

    The comparison, where the gap lies, the base model's update from the random test, which effect, and the additive
    explanation step by step.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): the whole of it is read (``verdict``, ``reason``, ``where``,
        ``resolution``, ``damping_at_test_level``, ``trace``, ``explanation``...).

    Returns
    -------
    text : str
        The paragraphs in LaTeX, newline-terminated lines.
    """
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
    """Return what these records can attribute to an effect (diagnosis.json's resolution), in words.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``resolution`` (``how``, ``isolability``) is read.

    Returns
    -------
    text : str
        The paragraph in LaTeX.
    """
    r = diag["resolution"]
    iso = r.get("isolability") or {}
    pairs = iso.get("pairs") or []
    text = r"\paragraph{Resolution.} " + _t(r["how"]) + ". "
    if pairs:
        text += (
            r"These records cannot tell apart (their signatures on the held-out records, with what "
            + (" and ".join(_t(f) for f in iso.get("form_removed") or []) or "the base model's form")
            + r" absorbs removed, point the same way, cosine above $"
            + latex_number(iso.get("limit", float("nan")), 2)
            + r"$): "
            + "; ".join(
                " and ".join(_t(c) for c in p["candidates"]) + r" ($" + latex_number(p["cosine"], 3) + r"$)"
                for p in pairs
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
        return "$" + latex_number(v, 3) + "$"
    return _t(str(v))


def trace_text(diag: dict) -> str:
    """Return the decisions the verdict was told by, in order (diagnosis.json's trace).

    Each: test, the step it judged, value against threshold, passed or not.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``trace`` is read.

    Returns
    -------
    text : str
        The paragraph in LaTeX.
    """
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
