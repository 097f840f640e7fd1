"""The gap section's paragraph 'The base model': the structure updated from the random test.

Chi^2 before and after against its bar, accepted or not and by what, what the data bind, the channels' relative
gains, from diagnosis.json's ``where.model_updating``.
"""

from __future__ import annotations

from ..latex import latex_number
from ..latex import plain_text as _t
from .report_format import num, pct
from .verdict import at_floor


def _factor_list(factors: dict) -> str:
    return ", ".join(_t(k) + r" $\times" + latex_number(float(v), 4) + "$" for k, v in factors.items())


def _records_verdict(rt: dict | None) -> str:
    """Return the dual-sine records' test of an update (``records_test``) in words, or "" where it was not run."""
    if not rt:
        return ""
    return (
        r"held-out gap "
        + pct(rt.get("heldout_gap_chain"))
        + r" with the nominal structure, "
        + pct(rt.get("heldout_gap_updated"))
        + r" with the update, the records' scatter "
        + pct(rt.get("record_scatter"))
        + (r", the preload drift refitted on each model" if "preload_drift" in rt else "")
    )


def _why_not(rt: dict, floor) -> str:
    """Return why the dual-sine records did not accept an update.

    Nothing above the floor to explain, or too little explained (``verdict.records_accept_update``).
    """
    gap = rt.get("heldout_gap_chain")
    if gap is not None and floor is not None and at_floor(float(gap), {"min_gap": float(floor)}):
        return r": the nominal structure's gap lies at the identification's floor, gap.min\_gap " + pct(floor)
    return r": the update does not shrink it by gap.min\_reduction beyond the records' scatter"


def _identifiability_text(ident: dict) -> str:
    """Return what the random test binds and what it leaves at its prior.

    Each bound factor with its posterior sd, on its log: relative.
    """
    factors = {k: v for k, v in ident.items() if k not in ("k_t", "k_n") and isinstance(v, dict)}
    bound = [(k, v) for k, v in factors.items() if v.get("bound_by_data")]
    free = [k for k, v in factors.items() if not v.get("bound_by_data")]
    text = ""
    if bound:
        text += (
            r" The random test binds "
            + ", ".join(_t(k) + r" ($\pm$\," + pct(v.get("posterior_sd")) + ")" for k, v in bound)
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
    """Return the accelerometer channels' sensitivities relative to one another (the random test's residues)."""
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
            f"channel {i + 1} ${latex_number(float(g), 4)}$" + (r" ($\pm$\," + pct(s) + ")" if s is not None else "")
            for i, (g, s) in enumerate(zip(gains, list(sd) + [None] * (len(gains) - len(sd))))
        )
        + significance
        + r". "
        + _gains_versus_structure_text(upd.get("gains_versus_structure"))
        + r"The channel-gain candidate applies them as they are."
    )


def _gains_versus_structure_text(test: dict | None) -> str:
    """Return what the dual-sine records chose where the random test could not tell gains from structure.

    The random test could not tell the channels' gains from the structure's factors; the records' test is
    ``evidence.records_test_of_gains``.
    """
    if not test:
        return ""
    return (
        r"But the structure's factors alone fit the random test as well ($\chi^2$ lower by "
        + latex_number(num(test.get("gains_drop")), 3)
        + r" with the gains, "
        + latex_number(num(test.get("gains_threshold")), 3)
        + r" needed), so the dual-sine records chose: held-out gap "
        + pct(test.get("heldout_gap_gains"))
        + r" with the update read through the gains, "
        + pct(test.get("heldout_gap_structure"))
        + r" with the structure alone (the records' scatter "
        + pct(test.get("record_scatter"))
        + r"); the update is made "
        + (r"with the gains. " if test.get("gains_preferred") else r"without them. ")
    )


def updating_paragraph(diag: dict) -> str:
    """Return the paragraph 'The base model': the structure updated from the random test.

    Chi^2 before and after against its bar, accepted or not and by what, what the data bind, the channels' relative
    gains.

    Parameters
    ----------
    diag
        The gap diagnosis (diagnosis.json as a dict): its ``where.model_updating`` and ``remaining_gap.floor`` are
        read.

    Returns
    -------
    paragraph : str
        The paragraph in LaTeX; "" without an update.
    """
    upd = (diag.get("where") or {}).get("model_updating")
    if not upd:
        return ""
    chi2 = (
        r"$\chi^2$ "
        + latex_number(num(upd.get("chi2_nominal")), 3)
        + r" for the nominal structure, "
        + latex_number(num(upd.get("chi2_updated")), 3)
        + r" for the best update ("
        + str(upd.get("n_data", "--"))
        + r" data); "
        + (
            r"a drop of "
            + latex_number(num(upd.get("chi2_threshold")), 3)
            + r" is significant for the "
            + latex_number(num(upd.get("effective_factors")), 2)
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
