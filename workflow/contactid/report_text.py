"""The report's text from the results: the values its macros quote, its sentences, paragraphs and two tables.

The numbers the text quotes (``report_values``, written as macros by ``contactid.latex.macros``), the sentences and
paragraphs said of the load cases, the test damping, the data and model checks and the records' disagreements, and
the contact-force and structure tables; the LaTeX formatting they use (numbers, escaping, tables) is
``contactid.latex``'s.
"""

from __future__ import annotations

import re
from typing import Any, Mapping

import pandas as pd

from .latex import escape, latex_number, plain_text, tabular
from .model_checks import FRICTION_CONSEQUENCE, FRICTION_FINDING, STIFFNESS_CONSEQUENCE, STIFFNESS_FINDING
from .test_damping import ratio_words


def case_words(case: str) -> str:
    """Return a load case's name in the report's text: "lc4" -> "load case 4".

    Parameters
    ----------
    case
        The load case's name (``lc<n>``; any other name is returned as it is).

    Returns
    -------
    words : str
        The name in words.
    """
    return f"load case {case[2:]}" if re.fullmatch(r"lc[0-9]+", case) else case


def _case_order(case: str):
    return (0, int(case[2:])) if re.fullmatch(r"lc[0-9]+", case) else (1, case)


def validation_text(validation: Mapping[str, float], calibration_case: str) -> str:
    """Return the report's sentence on how the fitted law predicts the load cases it was not fitted on.

    Without its full stop; the NRMSE printed in %, for any number of cases: one, several, or none (then it says so).

    Parameters
    ----------
    validation
        NRMSE of the law's prediction per load case, as a fraction [-] (summary.json's ``validation_nrmse``).
    calibration_case
        The case the law was fitted on (left out of the sentence).

    Returns
    -------
    sentence : str
        The sentence, in LaTeX.
    """
    others = sorted((c for c in validation if c != calibration_case), key=_case_order)
    if not others:
        return "One load case is configured, so there is no other for the law to predict"
    parts = [rf"\ensuremath{{{latex_number(100 * validation[c])}}}\,\% ({case_words(c)})" for c in others]
    listed = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
    return f"The law predicts the other load case{'s' if len(others) > 1 else ''} with NRMSE {listed}"


def report_values(
    summary: Mapping[str, Any],
    consistency: pd.DataFrame,
    calibration_case: str | None = None,
    figure_case: str | None = None,
) -> dict:
    r"""Return the numbers the report's text quotes, flattened into named values.

    ``calibration_case`` (the friction law's fit) and ``figure_case`` (Figs. 4 and 5) name the load cases the text
    quotes, so the text holds for any set of load cases; each case's own values are there too (``lc1recon`` ->
    ``\lconerecon``).

    Parameters
    ----------
    summary
        summary.json's content: reads ``natural_frequencies_hz``, ``stiction`` (k_t, k_n or ``k_n_lower_bound``,
        their intervals, ``stiffness_scale`` and its sd), ``truth`` (rig records only), ``contact_forces`` and
        ``contact_forces_paper`` per case, ``friction`` (the law, its intervals, ``test_damping``) and
        ``validation_nrmse``.
    consistency
        The paper-consistency table (``consistency.paper_consistency_table``).
    calibration_case
        The friction law's calibration case (``nonlinear.calibration_case``); None or not among the cases: the first
        configured.
    figure_case
        The case of Figs. 4 and 5 (``nonlinear.figure_case``); None or not among the cases: the last configured.

    Returns
    -------
    values : dict
        Key -> value, for ``macros``: numbers in the report's units (frequencies in Hz, stiffnesses in N/m, the
        consistency table's lever arms in mm and E in GPa, errors and NRMSEs in %, phase spread in deg), text
        fragments in LaTeX, and the switch ``rigtruth``.
    """
    v: dict = {}
    f = summary["natural_frequencies_hz"]
    for i, x in enumerate(f, start=1):
        v[f"freq{i}"] = x
    st = summary["stiction"]
    v["kt"] = st["k_t"]
    sd = float(st.get("stiffness_scale_sd", 0.0))
    v["stiffnessclause"] = (
        rf", with Young's modulus free within a prior of ${latex_number(100 * sd, 2)}\,\%$ sd (fitted: "
        rf"${latex_number(st['stiffness_scale'], 4)}$ times the model's),"
        if sd > 0
        else ", with the model's Young's modulus,"
    )
    v["ktlow"], v["kthigh"] = st["k_t_interval"]
    # knclause: what the report says of k_n, a value with its interval or, where the frequencies bound it from below
    # only, that bound (an interval with no upper end printed as "lower--{--}" read as a typesetting slip)
    if "k_n" in st:
        v["kn"] = st["k_n"]
        v["knlow"], v["knhigh"] = st["k_n_interval"]
        v["knstatement"] = "bounded on both sides"
        v["knclause"] = (
            rf"$k_n = {latex_number(st['k_n'])}$\,N/m, bounded on both sides (interval ${latex_number(v['knlow'])}$--"
            rf"${latex_number(v['knhigh'])}$)"
        )
    else:
        v["kn"] = st["k_n_lower_bound"]
        v["knlow"], v["knhigh"] = st["k_n_lower_bound"], float("inf")
        v["knstatement"] = "bounded from below only"
        v["knclause"] = (
            rf"$k_n \geq {latex_number(st['k_n_lower_bound'])}$\,N/m: the frequencies bound it from below only"
        )
    tr = summary.get("truth", {})
    # rigtruth: the records come from the virtual rig and its truth is known (the report's text scores against it);
    # false for measured records, where the report says what it compares with instead
    v["rigtruth"] = bool(tr)
    if tr:
        for i, x in enumerate(tr["natural_frequencies_hz"], start=1):
            v[f"truefreq{i}"] = x
        v["truekt"] = tr["stiction"]["k_t"]
        v["truekn"] = tr["stiction"]["k_n"]
    c = consistency.set_index("scenario")
    for sc in c.index:
        v[f"cons{sc}maxerr"] = c.loc[sc, "max_abs_err_pct"]
        v[f"cons{sc}kt"] = c.loc[sc, "k_t_n_per_m"]
        v[f"cons{sc}lever"] = 1e3 * c.loc[sc, "tangential_lever_arm_m"]
        v[f"cons{sc}E"] = 1e-9 * c.loc[sc, "youngs_modulus_pa"]
    for case, w in summary.get("contact_forces", {}).items():
        for q in ("S", "N", "xi", "eta"):
            if f"{q}_nrmse" in w:
                v[f"{case}work{q}"] = 100 * w[f"{q}_nrmse"]
                v[f"{case}paper{q}"] = 100 * summary["contact_forces_paper"][case][f"{q}_nrmse"]
        v[f"{case}knfromneta"] = w["normal_stiffness_from_n_eta_n_per_m"]
        p = summary["contact_forces_paper"][case]
        v[f"{case}phase"] = max(p["nnm_phase_spread_deg"])
        v[f"{case}recon"] = 100 * p["reconstruction_nrmse"]
    fr = summary.get("friction")
    if fr:
        for k in ("e_f", "k_c", "e_t", "kappa", "mu", "e0_at_preload"):
            v[f"fit{k}"] = fr[k]
            v[f"fit{k}low"], v[f"fit{k}high"] = fr["intervals"][k]
        v["fitcorr"] = fr["correlation_e_f_k_c"]
        for case, x in summary.get("validation_nrmse", {}).items():
            v[f"{case}validation"] = 100 * x
        v["testdampingtext"] = test_damping_text(fr.get("test_damping"))
    cases = sorted(summary.get("contact_forces", {}), key=_case_order)
    if cases:
        cal = calibration_case if calibration_case in cases else cases[0]
        fig = figure_case if figure_case in cases else cases[-1]
        v["calcase"], v["figcase"] = case_words(cal), case_words(fig)
        v["calknfromneta"] = v[f"{cal}knfromneta"]
        v["figcaserecon"], v["figcasephase"] = v[f"{fig}recon"], v[f"{fig}phase"]
        v["validationtext"] = validation_text(summary.get("validation_nrmse", {}), cal)
    return v


def test_damping_text(td: Mapping[str, Any] | None) -> str:
    """Return the report's sentence on the structure's damping in the dual-sine tests.

    From summary.json's ``friction.test_damping`` (rule test_damping): the factor the calibration record binds, and
    whether the held-out load cases confirmed it.

    Parameters
    ----------
    td
        summary.json's ``friction.test_damping`` (``form``, ``driven_mode``, ``interval``, ``scale``, ``accepted``
        and, where they were scored, the held-out gaps); None or empty: the random test's damping ratios were used.

    Returns
    -------
    sentence : str
        The sentence(s), in LaTeX.
    """
    if not td:
        return "The dual-sine tests were identified with the random test's damping ratios."
    which = ratio_words(td["form"], td["driven_mode"])
    lo, hi = td["interval"]
    bound = (
        rf"The law's misfit on the calibration record is least with {which} ${latex_number(td['scale'], 3)}$ times the "
        rf"random test's (${latex_number(lo, 3)}$--${latex_number(hi, 3)}$ within its profile threshold)"
    )
    if abs(td["scale"] - 1.0) < 1e-9:
        return "The law's misfit on the calibration record is least with the random test's damping ratios; they stand."
    gaps = ""
    if "heldout_gap_test_damping" in td:
        gaps = (
            rf" (held-out gap ${latex_number(100 * td['heldout_gap_random_test_damping'], 3)}\,\%$ with the "
            rf"random test's ratios, ${latex_number(100 * td['heldout_gap_test_damping'], 3)}\,\%$ with the factor)"
        )
    if td["accepted"]:
        return (
            f"{bound}; the other load cases confirm it{gaps}, so the contact forces and the law are identified with it."
        )
    return f"{bound}; the other load cases do not confirm it{gaps}, so the random test's ratios stand."


def contact_fragment(contact: pd.DataFrame) -> str:
    """Return the report's contact-force fragment.

    The NRMSE (%) of the identified contact forces and motions against the rig truth, working method and the paper's
    chain, one row per case; where no case has a truth (measured records), a paragraph saying what tests them instead.

    Parameters
    ----------
    contact
        One row per ``case``: NRMSE in % of the working method (columns ``w_S``, ``w_N``, ``w_xi``, ``w_eta``) and of
        the paper's chain (``p_S``, ``p_N``, ``p_xi``, ``p_eta``), NaN where there is no truth.

    Returns
    -------
    tex : str
        The table, or the paragraph, in LaTeX.
    """
    if contact.drop(columns="case", errors="ignore").isna().all().all():
        return (
            "\\paragraph{Contact forces against what?} The records are measured: no truth is known to score the "
            "identified contact forces and motions against. Fig.~\\ref{fig:forces} shows them; the friction law fitted "
            "on them and its prediction of the other load cases (Section~\\ref{sec:friction}), and the gap section's "
            "comparison of the identified model with the records, are what test them.\n"
        )
    return tabular(
        contact,
        {
            "case": "case",
            "w_S": "$S$",
            "w_N": "$N$",
            "w_xi": "$\\xi$",
            "w_eta": "$\\eta$",
            "p_S": "$S$ (paper)",
            "p_N": "$N$ (paper)",
            "p_xi": "$\\xi$ (paper)",
            "p_eta": "$\\eta$ (paper)",
        },
        "NRMSE (\\%) of the identified contact forces and motions against the rig truth: "
        "working method and the paper's chain.",
        "tab:contact",
    )


PAPER_GIVEN = {
    "shortening_scale",
    "length_m",
    "width_m",
    "thickness_m",
    "radius_m",
    "normal_lever_arm_m",
    "excitation_position_m",
    "positions_m",
    "preload_n",
    "block.mass_kg",
}


def setup_table(structure_cfg: Mapping[str, Any]) -> str:
    """Return the structure's values as a LaTeX table, each marked as the paper's or ours.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` mapping: every leaf of the nested mapping is a row (values in the units their keys
        name), the keys of ``PAPER_GIVEN`` marked as the paper's.

    Returns
    -------
    table : str
        The table environment, in LaTeX.
    """
    rows = []

    def walk(d, prefix=""):
        for k, v in d.items():
            key = f"{prefix}{k}"
            if isinstance(v, Mapping):
                walk(v, key + ".")
            else:
                given = k in PAPER_GIVEN or key in PAPER_GIVEN
                rows.append(
                    {
                        "quantity": key,
                        "value": ", ".join(latex_number(x) for x in v)
                        if isinstance(v, list)
                        else ("rigid" if v is None else v),
                        "source": "paper" if given else "ours",
                    }
                )

    walk(structure_cfg)
    lines = [
        r"\begin{table}[htbp]",
        r"\centering\footnotesize",
        r"\caption{The structure model. Values marked \emph{ours} are not given by the paper; "
        r"config/README.md gives the reasoning for each.}\label{tab:setup}",
        r"\begin{tabular}{llc}",
        r"\toprule",
        r"quantity (config key) & value & source \\",
        r"\midrule",
    ]
    for r in rows:
        val = r["value"]
        val = (
            f"${latex_number(val)}$"
            if isinstance(val, (int, float))
            else f"${val}$"
            if "times" in str(val)
            else str(val)
        )
        lines.append(f"{escape(r['quantity'])} & {val} & {escape(r['source'])} \\\\")
    lines += [r"\bottomrule", r"\end{tabular}", r"\end{table}"]
    return "\n".join(lines) + "\n"


def data_checks_text(summary: Mapping[str, Any]) -> str:
    """Return the report's paragraph on the raw records' validation: the checks, and each warning by record.

    Followed by the model checks' paragraph (``model_checks_text``).

    Parameters
    ----------
    summary
        summary.json's content: reads ``data_warnings`` (record -> list of warnings) and ``model_checks``.

    Returns
    -------
    tex : str
        The paragraphs, in LaTeX.
    """
    warnings = summary.get("data_warnings") or {}
    lines = [
        r"\paragraph{Data checks.} Every raw record passed the validation before identification (format, "
        r"finite samples, length and sampling rate for the harmonics and the FRF resolution, clipping, the "
        r"excitation frequency recovered from the force, stationarity of first against last third, the random "
        r"test's coherence in the modal band; thresholds in \texttt{raw\_checks})."
    ]
    items = [(rec, w) for rec, ws in sorted(warnings.items()) for w in ws]
    if not items:
        lines.append("No check came within a factor of two of its limit.")
    else:
        lines.append(r"Warnings (a value beyond half its limit):\begin{itemize}")
        lines += [rf"\item {plain_text(rec)}: {plain_text(w)}" for rec, w in items]
        lines.append(r"\end{itemize}")
    lines.append(model_checks_text(summary.get("model_checks") or []))
    return "\n".join(line for line in lines if line) + "\n"


def records_alert_text(summary: Mapping[str, Any]) -> str:
    """Return the report's first-page notice of records that disagree with each other or with the identified model.

    From summary.json's ``records_check`` (rule record_checks): each record named with the likely cause and its fix;
    empty (a comment) where every record agrees.

    Parameters
    ----------
    summary
        summary.json's content: reads ``records_check.findings`` (each with its ``message`` and, for a disagreement a
        units factor, a sign or a channel order explains, a ``signature``).

    Returns
    -------
    tex : str
        The boxed notice, or a comment line, in LaTeX.
    """
    findings = (summary.get("records_check") or {}).get("findings") or []
    if not findings:
        return "% every record agrees with the others and with the identified model (rule record_checks)\n"
    hard = any(f.get("signature") for f in findings)
    lines = [
        r"\begin{center}\fbox{\begin{minipage}{0.94\linewidth}",
        r"\textbf{Check the records first.} "
        + (
            "These records disagree with the others or with the identified model in a way a units factor, a sign "
            "or a channel order explains; the numbers below that use them are not to be trusted until they are "
            r"corrected, and the gap diagnosis looks for no effect (verdict records\_disagree):"
            if hard
            else "These records disagree grossly with the identified model in a way no units factor, sign or channel "
            "order explains (an effect it lacks at their level, which the gap section looks for, or a structure that "
            "changed between tests):"
        ),
        r"\begin{itemize}",
        *[rf"\item {plain_text(f['message'])}" for f in findings],
        r"\end{itemize}",
        r"\end{minipage}}\end{center}",
    ]
    return "\n".join(lines) + "\n"


TEX_SYMBOLS = {"k_t": "$k_t$", "k_n": "$k_n$", "S": "$S$"}  # the model checks' symbols in LaTeX


def model_checks_text(checks: list[Mapping[str, Any]]) -> str:
    """Return the report's paragraph on each fit against the accuracy it assumes.

    From ``contactid.model_checks`` (summary.json's ``model_checks``): a sentence per check, the consequence spelled
    out where one fails. Empty without checks.

    Parameters
    ----------
    checks
        One mapping per check: ``check`` (``stiffness_fit`` or ``friction_fit``), ``value``, ``limit``, ``passed``,
        and for the stiffness fit ``dof`` and ``p_value``.

    Returns
    -------
    paragraph : str
        The paragraph in LaTeX, or "" without checks.
    """
    said = []
    for c in checks:
        v, lim = float(c["value"]), float(c["limit"])
        if c["check"] == "stiffness_fit":
            dof = int(c["dof"])
            head = (
                rf"The stiffness fit leaves $\chi^2 = {latex_number(v, 3)}$ for {dof} "
                rf"degree{'s' if dof > 1 else ''} of freedom (limit ${latex_number(lim, 3)}$"
            )
            if c["passed"]:
                said.append(head + "): the structure with contact springs reproduces the identified frequencies.")
            else:
                said.append(
                    head
                    + rf", $p = {latex_number(c['p_value'], 2)}$): \textbf{{{STIFFNESS_FINDING}}}; "
                    + STIFFNESS_CONSEQUENCE.format(**TEX_SYMBOLS)
                    + "."
                )
        elif c["check"] == "friction_fit":
            head = rf"The friction law fits the identified $S$ to ${latex_number(100 * v, 3)}\,\%$ (NRMSE)"
            if c["passed"]:
                said.append(head + rf", within the ${latex_number(100 * lim, 3)}\,\%$ its intervals assume.")
            else:
                said.append(
                    head + rf", \textbf{{${latex_number(v / lim, 3)}$ times the "
                    rf"${latex_number(100 * lim, 3)}\,\%$ its intervals "
                    r"assume} (\texttt{friction.misfit\_floor}): "
                    + FRICTION_FINDING.format(**TEX_SYMBOLS)
                    + "; "
                    + FRICTION_CONSEQUENCE
                    + "."
                )
    if not said:
        return ""
    return r"\paragraph{Model checks.} Each fit against the accuracy it assumes. " + " ".join(said)
