"""The report's section on the sim-to-real gap.

The diagnosis of the configured data and, when built, the blind benchmark (text generated from diagnosis.json and
benchmark.json, no number typed by hand).

The section's assembly: ``gap_section``, the candidates' table, the figures it includes and the friction law's notes and
intervals; the diagnosis in words is ``report_diagnosis``'s (the base model's paragraph ``report_base_model``'s), the
benchmarks' paragraphs ``report_benchmark``'s, the shared number formatting ``report_format``'s.
"""

from __future__ import annotations

import pandas as pd

from ..latex import latex_number, tabular
from ..latex import plain_text as _t
from ..test_damping import ratio_words
from .report_benchmark import benchmark_text
from .report_diagnosis import diagnosis_paragraphs
from .report_format import num


def updated_law_note(intervals: dict | None) -> str:
    """Return a sentence for Table 4's caption where the random test's model updating changed the structure.

    Where friction_intervals.json's model is "updated", Table 4's law rests on the nominal structure, and the updated
    model's law, with its model-form intervals (``intervals_text``'s table), is the one to read. (A structure 12 %
    softer with accelerometers 60 % heavy: Table 4 gave mu 0.277 with an interval 0.224-0.324 that excludes the rig's
    0.397; the updated model 0.388, 0.312-0.482.)

    Parameters
    ----------
    intervals
        friction_intervals.json's content (model, parameters with value and interval); None: not built.

    Returns
    -------
    note : str
        The sentence (LaTeX), with a leading space; "" where the model is not the updated one.
    """
    if not intervals or intervals.get("model") != "updated":
        return ""
    par = intervals.get("parameters") or {}
    symbols = {"mu": r"\mu", "kappa": r"\kappa", "e0": r"e_0(N_0)"}
    parts = [
        f"${sym} = {latex_number(par[n]['value'], 3)}$ "
        f"(${latex_number(par[n]['interval'][0], 3)}$--${latex_number(par[n]['interval'][1], 3)}$)"
        for n, sym in symbols.items()
        if n in par
    ]
    return (
        " These rest on the nominal structure, which the random test's model updating changed; the updated model's "
        "law, with the model-form term (Table~\\ref{tab:intervals}), gives " + ", ".join(parts) + "."
    )


def explained_law_note(updated: dict | None) -> str:
    """Return a sentence for Table 4's caption where the gap diagnosis explained effects or applied test-level damping.

    Where the diagnosis explained effects, or applied the damping at test level the records confirm
    (results/gap/updated_model.json): the friction law refitted with them beside the chain's, which they bias.

    Parameters
    ----------
    updated
        results/gap/updated_model.json's content (effects, damping_at_test_level, friction); None: not built.

    Returns
    -------
    note : str
        The sentence (LaTeX), with a leading space; "" where the model is the chain's.
    """
    if not updated:
        return ""
    td = updated.get("damping_at_test_level") or {}
    if updated.get("effects"):
        what = "Refitted with the effects the gap diagnosis explains (" + ", ".join(_t(n) for n in updated["effects"])
        tail = "the chain's law above carries what those effects do to the identified S."
    elif td.get("applied"):
        which = ratio_words(td["form"], td["driven_mode"])
        scale = latex_number(td["scale"], 3)
        what = f"With {which} at test level, ${scale}$ times the random test's, as the other load cases confirm"
        tail = "the chain's law above carries the damping the random test misstates."
    else:
        return ""
    fr = updated["friction"]
    return (
        " "
        + what
        + r"; results/gap/updated\_model.json), the law is $\mu = "
        + latex_number(fr["mu"], 3)
        + r"$, $\kappa = "
        + latex_number(fr["kappa"], 3)
        + r"$, $e_0(N_0) = "
        + latex_number(fr["e0_at_preload"], 3)
        + "$~N/m: "
        + tail
    )


def intervals_text(intervals: dict | None) -> str:
    """Return the friction law's intervals with the model-form term as a paragraph and table.

    Parameters
    ----------
    intervals
        friction_intervals.json's content (model, n_structures, parameters with value, profile_interval, sd_cases,
        sd_structure, interval); None: left out.

    Returns
    -------
    text : str
        The paragraph and table (LaTeX); "" without intervals.
    """
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


def candidates_table(diag: dict) -> str:
    """Return the table of the candidates.

    The held-out gap before and after, its bootstrap interval and the shrink in %, the score.

    Parameters
    ----------
    diag
        diagnosis.json's content; its ``ranking`` is read.

    Returns
    -------
    table : str
        The table (LaTeX); empty without candidates.
    """
    rows = pd.DataFrame(
        [
            {
                "effect": r["effect"] + ("*" if r.get("settles_unlike_records") else ""),
                "k": r["n_parameters"],
                "before": 100 * num(r["heldout_gap_before"]),
                "after": 100 * num(r["heldout_gap_after"]),
                "low": 100 * num(r["heldout_gap_after_interval"][0]),
                "high": 100 * num(r["heldout_gap_after_interval"][1]),
                "reduction": 100 * num(r["reduction"]),
                "score": num(r["score"]),
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
    """Return a gap figure at the report's text width, the width it is drawn at (print_style): text >= 8 pt on paper."""
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


def gap_section(diag: dict, bench: dict | None, intervals: dict | None = None) -> str:
    """Return the report's section on the gap (LaTeX).

    Parameters
    ----------
    diag
        diagnosis.json's content.
    bench
        benchmark.json's content; None: not built.
    intervals
        friction_intervals.json's content; None: left out.

    Returns
    -------
    section : str
        The diagnosis's paragraphs, the candidates' table, the figures, the intervals and the benchmark's text.
    """
    return (
        diagnosis_paragraphs(diag)
        + candidates_table(diag)
        + GAP_FIGURES
        + intervals_text(intervals)
        + benchmark_text(bench)
    )
