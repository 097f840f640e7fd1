"""The gap section's paragraphs on the benchmarks, text generated from benchmark.json.

The blind benchmark, the compound one when built, the accuracy per effect; a note when the benchmark was not built.
"""

from __future__ import annotations

import pandas as pd

from ..latex import tabular
from .report_format import pct


def _bound_text(c: dict) -> str:
    """Return the compound benchmark's errors of what the data bind (mu a, e_0 a^2), when scored."""
    b = c.get("perturbation_only_median_abs_bound_error")
    if not b or any(v is None for v in b.values()):
        return ""
    return (
        r" What the data bind, with the model's lever arm $a$ against the rig's: median errors $\mu a$ "
        + pct(b["mu_a"])
        + r", $e_0 a^2$ "
        + pct(b["e0_a2"])
        + "."
    )


def _coverage_text(c: dict) -> str:
    """Return the compound benchmark's interval coverage (intervals with the model-form term), when scored."""
    cov, hw = c.get("perturbation_only_interval_coverage"), c.get("perturbation_only_median_interval_halfwidth")
    if not cov or not hw or any(cov.get(k) is None for k in ("mu", "kappa", "e0")):
        return ""
    symbols = (("mu", r"$\mu$"), ("kappa", r"$\kappa$"), ("e0", "$e_0$"), ("mu_a", r"$\mu a$"), ("e0_a2", "$e_0 a^2$"))
    shown = [(k, sym) for k, sym in symbols if cov.get(k) is not None and hw.get(k) is not None]
    return (
        r" The 95\,\% intervals with the model-form term (spread over load cases and over the structures "
        r"the random test allows) held the truth in: "
        + ", ".join(f"{sym} {pct(cov[k])}" for k, sym in shown)
        + r" of these sets, with median half-widths "
        + ", ".join(sym + r" $\pm$\," + pct(hw[k]) for k, sym in shown)
        + "."
    )


NO_BENCHMARK = (
    "\n\\paragraph{Blind benchmark.} Not built with this report (\\texttt{gap\\_benchmark.in\\_report: "
    "false}); run \\texttt{snakemake gap\\_benchmark}.\n"
)


def blind_paragraph(bench: dict) -> str:
    """Return the blind benchmark in words.

    Top-1 accuracy, false alarms, shrink of the correctly named effects (%), the left-out items and the median
    diagnosis time (s).

    Parameters
    ----------
    bench
        benchmark.json: reads ``n_blind``, ``top1_accuracy``, ``false_alarms``, ``n_effect_free``,
        ``shrink_of_correct`` (``min``, ``median``), ``leave_out`` (``n``, ``verdict_none``, ``place_right``) and
        ``diagnosis_seconds`` (``median``, in s); fractions as 0-1.

    Returns
    -------
    text : str
        The paragraph, in LaTeX.
    """
    lo = bench["leave_out"]
    return (
        "\n\\paragraph{Blind benchmark.} " + str(bench["n_blind"]) + r" rig data sets, each with one effect on at a "
        r"random (seeded) magnitude, diagnosed from their raw records alone: top-1 accuracy "
        + pct(bench["top1_accuracy"])
        + r"; false alarms on effect-free data: "
        + str(bench["false_alarms"])
        + " of "
        + str(bench["n_effect_free"])
        + r"; held-out gap shrink of the correctly named effects: smallest "
        + pct(bench["shrink_of_correct"]["min"])
        + r", median "
        + pct(bench["shrink_of_correct"]["median"])
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
    """Return the compound benchmark in words.

    Effects named (%), the remaining held-out gap and the friction law's errors after updating (%), with what the
    data bind and the intervals' coverage when scored.

    Parameters
    ----------
    c
        benchmark.json's ``compound`` block: reads ``n``, ``n_by_effect_count``, the shares
        ``perturbation_only_no_contact_effect``, ``one_effect_named``, ``one_effect_no_absent_contact_effect``,
        ``two_effects_both_named``, ``two_effects_one_named``, ``remaining_gap_median``,
        ``perturbation_only_median_abs_error`` (``mu``, ``kappa``, ``e0``) and, when scored, the bound errors and the
        intervals' coverage and half-widths; fractions as 0-1.

    Returns
    -------
    text : str
        The paragraph, in LaTeX.
    """
    err = c["perturbation_only_median_abs_error"]
    return (
        "\n\\paragraph{Compound benchmark.} " + str(c["n"]) + r" rig data sets whose structure (E, transducer "
        r"masses, tangential lever arm; on half of them a clamp that gives), normal law and damping form differ "
        r"from the model's at random, with 0, 1 or 2 effects ("
        + ", ".join(f"{v} with {k}" for k, v in c["n_by_effect_count"].items())
        + r"), diagnosed "
        r"with model updating and scored on the additive explanation. Perturbation only: no contact effect named "
        r"in "
        + pct(c["perturbation_only_no_contact_effect"])
        + r"; one effect: named in "
        + pct(c["one_effect_named"])
        + r", no absent contact effect in "
        + pct(c["one_effect_no_absent_contact_effect"])
        + r"; two effects: both named in "
        + pct(c["two_effects_both_named"])
        + r", at least one in "
        + pct(c["two_effects_one_named"])
        + r". Median remaining held-out gap "
        + pct(c["remaining_gap_median"])
        + r". Perturbation only, after updating, median errors: $\mu$ "
        + pct(err["mu"])
        + r", $\kappa$ "
        + pct(err["kappa"])
        + r", $e_0$ "
        + pct(err["e0"])
        + r" (the tangential lever arm, which linear data do not "
        r"bound, scales the identified $S$ and so $\mu$)." + _bound_text(c) + _coverage_text(c)
    ) + "\n"


def accuracy_table(bench: dict) -> str:
    """Return the blind benchmark's top-1 accuracy per effect (%) as a table, and the confusion matrix's figure.

    Parameters
    ----------
    bench
        benchmark.json: reads ``per_effect_accuracy`` ({effect: accuracy as 0-1}).

    Returns
    -------
    text : str
        The table and the figure (confusion.png), in LaTeX.
    """
    acc = pd.DataFrame([{"effect": e, "accuracy": 100 * a} for e, a in bench["per_effect_accuracy"].items()])
    return tabular(
        acc, {"effect": "effect", "accuracy": "top-1 (\\%)"}, "Blind benchmark: accuracy per effect.", "tab:bench"
    ) + (
        "\\begin{figure}[H]\\centering\\includegraphics[width=0.6\\textwidth]{confusion.png}"
        "\\caption{Blind benchmark: confusion matrix.}\\label{fig:confusion}\\end{figure}\n"
    )


def benchmark_text(bench: dict | None) -> str:
    """Return the benchmarks' part of the section.

    The blind benchmark, the compound one when built, the accuracy table; a note when the benchmark was not built.

    Parameters
    ----------
    bench
        benchmark.json (``blind_paragraph``, ``compound_paragraph``, ``accuracy_table``); None: not built.

    Returns
    -------
    text : str
        The text, in LaTeX.
    """
    if bench is None:
        return NO_BENCHMARK
    out = blind_paragraph(bench)
    c = bench.get("compound")
    if c:
        out += compound_paragraph(c)
    return out + accuracy_table(bench)
