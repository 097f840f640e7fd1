"""The result of model updating, ``UpdatingResult``, and its summary.

The factors, k_t and k_n, the updated structure, the misfits and the verdict, the identifiability of each parameter,
the proposal the records may accept, the structures the linearised posterior allows, and the summary written to
model_updating.json (and read back from it).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from .parameters import StructureParameters
from .updating_model import apply_factors, modal_predictions


@dataclass
class UpdatingResult:
    """The update of the structure from the random test's modal fit (``contactid.updating.update_structure``).

    Attributes
    ----------
    factors
        {factor name (``updating_model.FACTORS``): multiplier of its nominal value [-]}.
    k_t
        The tangential contact stiffness of Eq. 13 [N/m].
    k_n
        The normal contact stiffness of Eq. 13 [N/m].
    structure
        The updated structure (the nominal one with these factors, k_t and k_n).
    chi2_nominal
        The data misfit chi^2 of the nominal structure, k_t and k_n refitted [-].
    chi2_updated
        The data misfit chi^2 after the update [-].
    accepted
        Whether the update is accepted (see ``accepted_by``).
    identifiability
        Per parameter (k_t, k_n and each factor): its posterior sd and prior sd (of its ln) and their ratio, whether
        the data bound it, the parameter it correlates with most (with the correlation); for each factor the posterior
        misfit's rise when it is held at nominal (its profile), alone and with its ``PROFILE_GROUPS`` group.
    model_frequencies_hz
        The updated structure's natural frequencies [Hz], shape (n_modes,), the identified modes compared; None
        where not kept (a result read back from its summary).
    n_data
        The number of data the misfit counts (frequencies and residues).
    covariance
        The linearised posterior covariance of (ln k_t, ln k_n, ln factors), a nested list of shape
        (2 + n_factors, 2 + n_factors); None where not computed.
    nominal
        The structure the factors multiply; None where not given.
    proposal
        The update the chi^2 test did not accept: {"factors", "k_t", "k_n"} (None when accepted).
    accepted_by
        What accepted it: "random_test" (the chi^2 test), "records" (the dual-sine records' held-out gap), ""
        (nothing).
    records_test
        The records' test of the proposal (when run): held-out gaps, scatter, the drift where they drift.
    chi2_threshold
        The drop of chi^2 the random test needed (``chi2_drop_threshold``) [-]; NaN where unknown, inf where no drop
        is significant.
    effective_factors
        The sum of the drop's null weights, the number of factors the data bind [-] (``null_drop_weights``; 5 bound
        factors: 5 and chi^2_5(0.95) = 11.07).
    channel_gains
        Each accelerometer channel's sensitivity factor on its residues relative to the others' (their logs sum to
        zero), fitted with k_t and k_n as the measurement chain's; empty when update_structure's gain_sd is 0:
        reported, the structure is not multiplied by them.
    channel_gain_sd
        The posterior sd of each channel gain's ln.
    channel_gains_significant
        Whether the gains lowered the nominal structure's chi^2 significantly (and so took part in the update's
        fit).
    structure_alone
        Where the gains took part: the same update without them (its ``summary``), with ``gains_drop`` (its chi^2
        less this update's), ``gains_threshold`` (chi^2_(j-1)(confidence)) and ``gains_needed`` (the drop above it:
        the residues call for the gains beyond what the structure's factors give); None where the gains took no
        part.
    gains_versus_structure
        Where the random test could not tell the gains from the structure: the dual-sine records' test that chose
        (``gap.evidence.records_test_of_gains``: both held-out gaps, the records' scatter, ``gains_preferred``).
    """

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
        """Return the result written by ``summary``, with the structure rebuilt by the same factors, k_t and k_n.

        Parameters
        ----------
        summary
            The result's ``summary`` (model_updating.json's content).
        params
            The configured (nominal) structure the factors multiply.

        Returns
        -------
        result : UpdatingResult
            The result, without ``model_frequencies_hz``.
        """
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
        """Return the update made without the channel gains (``structure_alone``).

        The gains are still reported (as the nominal structure's residues show them) but not significant: the random
        test cannot tell them from the structure's factors (``gains_needed`` false) and the dual-sine records did not
        call for them (``gap.base_model.updated_model``).

        Returns
        -------
        result : UpdatingResult
            The update without the gains.

        Raises
        ------
        ValueError
            When the gains took no part in the update (no ``structure_alone``) or the nominal structure is unknown.
        """
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
        """Return the structure of the ``proposal``: the nominal structure with its k_t, k_n and factors.

        Returns
        -------
        structure : StructureParameters
            The proposed structure.

        Raises
        ------
        ValueError
            When there is no proposal (the update was accepted or never computed) or the nominal structure is unknown.
        """
        if self.proposal is None or self.nominal is None:
            raise ValueError("model updating: no proposal to accept (the update was accepted or never computed)")
        p = self.proposal
        return apply_factors(self.nominal.with_contact(float(p["k_t"]), float(p["k_n"])), p["factors"])

    def accept_proposal(self, records_test: dict) -> "UpdatingResult":
        """Return this result with its ``proposal`` accepted by the dual-sine records.

        The result takes the proposal's factors, k_t, k_n and structure; the identifiability (with each factor's
        profile) is already the proposal's. Without a proposal, ``proposed_structure`` raises ValueError.

        Parameters
        ----------
        records_test
            What the dual-sine records showed (``gap.evidence.records_test_of_update``), kept for the audit.

        Returns
        -------
        result : UpdatingResult
            The accepted update (``accepted_by`` "records").
        """
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
        """Return the structures the random test allows.

        They are the update moved by +-1 standard deviation along each principal axis of the linearised posterior
        of (ln k_t, ln k_n, ln factors), for observability tests (one parameter at a time would leave the data's
        valley: E alone by its marginal sd moves the frequencies far more than the data allow).

        Returns
        -------
        structures : list
            StructureParameters in +- pairs, minus first, two per axis (2 (2 + n_factors) of them); empty without a
            covariance or a nominal structure.
        """
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
        """Return the update as written to model_updating.json (read back by :meth:`from_summary`).

        Returns
        -------
        summary : dict
            JSON-ready fields of the result (not the structures nor the model frequencies); ``chi2_threshold`` None
            where it is infinite.
        """
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
    """Return chi2_threshold as model_updating.json keeps it.

    Null stands for inf (no drop significant); the key is missing in older files (NaN).
    """
    return math.inf if value is None else float(value)
