"""The result of model updating, ``UpdatingResult``, and its summary. The factors, k_t and k_n, the updated structure,
the misfits and the verdict, the identifiability of each parameter, the proposal the records may accept, the structures
the linearised posterior allows, and the summary written to model_updating.json (and read back from it)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from .parameters import StructureParameters
from .updating_model import apply_factors, modal_predictions


@dataclass
class UpdatingResult:
    """The update: the factors (name -> multiplier of the nominal value), k_t, k_n (N/m), the updated
    structure, the data misfit chi^2 before (nominal structure, k_t and k_n refitted) and after, whether the
    update is accepted, and per parameter its posterior sd over prior sd, whether the data bound it, and the
    parameter it correlates with most (with the correlation)."""

    factors: dict
    k_t: float
    k_n: float
    structure: StructureParameters
    chi2_nominal: float
    chi2_updated: float
    accepted: bool
    identifiability: dict = field(default_factory=dict)
    model_frequencies_hz: np.ndarray | None = None
    n_data: int = 0
    covariance: list | None = None  # of (ln k_t, ln k_n, ln factors), linearised posterior
    nominal: StructureParameters | None = None  # the structure the factors multiply
    # the update the chi^2 test did not accept: {"factors", "k_t", "k_n"} (None when accepted)
    proposal: dict | None = None
    # what accepted it: "random_test" (the chi^2 test), "records" (the dual-sine records' held-out gap), "" (nothing)
    accepted_by: str = ""
    # the records' test of the proposal (when run): held-out gaps, scatter, the drift where they drift
    records_test: dict | None = None
    # the drop of chi^2 the random test needed (chi2_drop_threshold) and the sum of its null weights, the number of
    # factors the data bind (null_drop_weights; 5 bound factors: 5 and chi^2_5(0.95) = 11.07)
    chi2_threshold: float = math.nan
    effective_factors: float = math.nan
    # each accelerometer channel's sensitivity factor on its residues relative to the others' (their logs sum to zero)
    # and the posterior sd of its ln (fitted with k_t and k_n as the measurement chain's; empty when update_structure's
    # gain_sd is 0): reported, the structure is not multiplied by them
    channel_gains: tuple = ()
    channel_gain_sd: tuple = ()
    # whether they lowered the nominal structure's chi^2 significantly (and so took part in the update's fit)
    channel_gains_significant: bool = False
    # where they took part: the same update without them (its ``summary``), with ``gains_drop`` (its chi^2 less this
    # update's), ``gains_threshold`` (chi^2_(j-1)(confidence)) and ``gains_needed`` (the drop above it: the residues
    # call for the gains beyond what the structure's factors give); None where the gains took no part
    structure_alone: dict | None = None
    # where the random test could not tell the gains from the structure: the dual-sine records' test that chose
    # (``gap.evidence.records_test_of_gains``: both held-out gaps, the records' scatter, ``gains_preferred``)
    gains_versus_structure: dict | None = None

    @classmethod
    def from_summary(cls, summary: dict, params: StructureParameters) -> "UpdatingResult":
        """The result written by ``summary`` (model_updating.json), with the structure rebuilt from ``params``
        (the configured structure) by the same factors, k_t and k_n."""
        p = apply_factors(params.with_contact(float(summary["k_t"]), float(summary["k_n"])), summary["factors"])
        return cls(
            dict(summary["factors"]),
            float(summary["k_t"]),
            float(summary["k_n"]),
            p,
            float(summary["chi2_nominal"]),
            float(summary["chi2_updated"]),
            bool(summary["accepted"]),
            dict(summary["identifiability"]),
            None,
            int(summary["n_data"]),
            summary["covariance"],
            params,
            summary.get("proposal"),
            str(summary.get("accepted_by", "random_test" if summary["accepted"] else "")),
            summary.get("records_test"),
            _threshold(summary.get("chi2_threshold", math.nan)),
            float(summary.get("effective_factors", math.nan)),
            tuple(summary.get("channel_gains") or ()),
            tuple(summary.get("channel_gain_sd") or ()),
            bool(summary.get("channel_gains_significant", False)),
            summary.get("structure_alone"),
            summary.get("gains_versus_structure"),
        )

    def without_gains(self) -> "UpdatingResult":
        """The update made without the channel gains (``structure_alone``), the gains still reported (as the nominal
        structure's residues show them) but not significant: the random test cannot tell them from the structure's
        factors (``gains_needed`` false) and the dual-sine records did not call for them
        (``gap.pipeline.updated_model``)."""
        if self.structure_alone is None or self.nominal is None:
            raise ValueError("model updating: no update without the channel gains (the gains took no part in it)")
        return dataclasses.replace(
            UpdatingResult.from_summary(self.structure_alone, self.nominal),
            channel_gains=tuple(self.structure_alone.get("nominal_channel_gains", self.channel_gains)),
            channel_gain_sd=tuple(self.structure_alone.get("nominal_channel_gain_sd", self.channel_gain_sd)),
            channel_gains_significant=False,
            structure_alone=None,
        )

    def proposed_structure(self) -> StructureParameters:
        """The structure of the ``proposal``: the nominal structure with its k_t, k_n and factors."""
        if self.proposal is None or self.nominal is None:
            raise ValueError("model updating: no proposal to accept (the update was accepted or never computed)")
        p = self.proposal
        return apply_factors(self.nominal.with_contact(float(p["k_t"]), float(p["k_n"])), p["factors"])

    def accept_proposal(self, records_test: dict) -> "UpdatingResult":
        """This result with its ``proposal`` accepted by the dual-sine records (``records_test``: what they showed,
        kept for the audit): the proposal's factors, k_t, k_n and structure; the identifiability (with each factor's
        profile) is already the proposal's."""
        structure = self.proposed_structure()
        factors = {k: float(v) for k, v in self.proposal["factors"].items()}
        k_t, k_n = float(self.proposal["k_t"]), float(self.proposal["k_n"])
        n = 0 if self.model_frequencies_hz is None else len(self.model_frequencies_hz)
        f_best = modal_predictions(structure, n)[0] if n else None
        return dataclasses.replace(
            self,
            factors=factors,
            k_t=k_t,
            k_n=k_n,
            structure=structure,
            accepted=True,
            model_frequencies_hz=f_best,
            proposal=None,
            accepted_by="records",
            records_test=dict(records_test),
        )

    def posterior_structures(self) -> list:
        """The structures the random test allows: the update moved by +-1 standard deviation along each principal
        axis of the linearised posterior of (ln k_t, ln k_n, ln factors), for observability tests (one parameter
        at a time would leave the data's valley: E alone by its marginal sd moves the frequencies far more
        than the data allow)."""
        if self.covariance is None or self.nominal is None:
            return []
        cov = np.asarray(self.covariance, float)
        lam, vec = np.linalg.eigh(cov)
        x = np.log([self.k_t, self.k_n] + [self.factors[f] for f in self.factors])
        names = list(self.factors)
        out = []
        for lam_i, v in zip(lam, vec.T):
            for sign in (-1.0, 1.0):
                y = x + sign * np.sqrt(max(lam_i, 0.0)) * v
                out.append(
                    apply_factors(
                        self.nominal.with_contact(float(np.exp(y[0])), float(np.exp(y[1]))),
                        {f: float(np.exp(val)) for f, val in zip(names, y[2:])},
                    )
                )
        return out

    def summary(self) -> dict:
        """The update as written to model_updating.json (read back by :meth:`from_summary`)."""
        return {
            "accepted": self.accepted,
            "factors": dict(self.factors),
            "k_t": self.k_t,
            "k_n": self.k_n,
            "chi2_nominal": self.chi2_nominal,
            "chi2_updated": self.chi2_updated,
            "n_data": self.n_data,
            "identifiability": self.identifiability,
            "covariance": self.covariance,
            "proposal": self.proposal,
            "accepted_by": self.accepted_by,
            "records_test": self.records_test,
            "chi2_threshold": self.chi2_threshold if math.isfinite(self.chi2_threshold) else None,  # null: inf
            "effective_factors": self.effective_factors,
            "channel_gains": list(self.channel_gains),
            "channel_gain_sd": list(self.channel_gain_sd),
            "channel_gains_significant": self.channel_gains_significant,
            "structure_alone": self.structure_alone,
            "gains_versus_structure": self.gains_versus_structure,
        }


def _threshold(value) -> float:
    """chi2_threshold as model_updating.json keeps it: null for inf (no drop significant), missing in older files."""
    return math.inf if value is None else float(value)
