"""Model updating of the base (linear) structure from the random test, before contact effects are tried.

The identified model assumes the configured ``structure``; a real rig is a few per cent off everywhere.
The random test's modal fit gives the natural frequencies f_i (with their standard errors) and the
magnitudes of the accelerance residues |R_si| = |phi_i(x_s) phi_i(x_d)| / (2 omega_i) (mass-normalised
shapes at the sensors and the drive point), which carry the mode shapes and the mass scaling, not the
frequencies alone. Updating fits the stuck contact's k_t, k_n and scale factors of the structure to both,
as a maximum a posteriori estimate: each structural factor x_j = ln(theta_j / theta_j,nominal) has a
Gaussian prior N(0, s_j^2) (its plausible spread about the nominal value), so parameters the data do not
bound stay at their nominal values instead of wandering along a valley. The clamp's factor scales its rotational
compliance 1/k_c, a rigid clamp taken as CLAMP_RIGID once it moves; as a rigid clamp gives the fit no gradient, the fit
is started again from each factor's further ``starts`` and keeps the lower posterior misfit. The force transducer's
mass has a factor of its own beyond the common one of every transducer (a rig's transducers are off apart).

Identifiability is stated per parameter from the linearised posterior: the posterior standard deviation
over the prior's (``posterior_over_prior``); a ratio below IDENTIFIED (0.5) means the data bound the
parameter, otherwise it is set by its prior. Each factor's profile (the posterior misfit's rise when it is held at
its nominal value) says whether it moved; the factors of a PROFILE_GROUPS group (the two transducer-mass factors, each
partly taken up by the other) are also held at nominal together. The strongest posterior correlation names the
parameter it trades off against (for example k_t against the tangential lever arm: the frequencies see about
a^2 k_t k_b / (k_t + k_b)).

The update is accepted when it lowers the data misfit chi^2 by more than the drop the nominal structure would give
with probability 1 - confidence (0.95 by default): chi^2_k(confidence) for k factors the data bind, less where the
data leave a factor at its prior (the drop's null distribution from the hat matrices of the prior-weighted fits,
``null_drop_weights``; a rigid clamp's compliance, a lever arm the data do not see add nothing to it). Otherwise the
nominal structure is kept and the update is offered as ``proposal``: the gap diagnosis may still accept it when it
shrinks the held-out gap of the dual-sine records materially (``UpdatingResult.accept_proposal``,
``gap.pipeline.updated_model``): with the frequency floor the random test alone cannot make transducer masses 7-22 %
off significant, yet the update finds them (docs/gap.md, "Model updating").
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, NamedTuple

import numpy as np

from .beam_model import assemble, structural_modes
from .finite_differences import central_difference_jacobian
from .parameters import StructureParameters

IDENTIFIED = 0.5  # posterior sd / prior sd below this: the data bound the parameter
DIFF_STEP = 1e-5  # finite-difference step of the MAP fit's Jacobian, absolute, on the logs of the parameters


@dataclass(frozen=True)
class StructuralFactor:
    """A structural parameter of the updating: its name, what it scales, the prior's relative spread s
    (of ln theta) and how it changes the structure."""

    name: str
    description: str
    prior_sd: float
    apply: Callable[[StructureParameters, float], StructureParameters]
    # further starts of the MAP fit (values of the factor): a factor whose effect vanishes at its nominal value (a
    # rigid clamp's compliance) has no gradient there, and a fit from the nominal value alone would not move it
    starts: tuple = ()
    max_prior_sd: float = 2.0  # the largest prior spread gap.model_updating.prior_sd may give it
    # whether the nominal structure needs the further starts (None: always); a finite clamp has a gradient already
    needs_starts: Callable[[StructureParameters], bool] | None = None


def _scale_masses(p: StructureParameters, m: float) -> StructureParameters:
    return p.replace(
        sensor_masses=tuple(m * x for x in p.sensor_masses), force_transducer_mass=m * p.force_transducer_mass
    )


def _scale_clamp_compliance(p: StructureParameters, m: float) -> StructureParameters:
    """The clamp's rotational compliance 1 / k_c times m; a rigid clamp (k_c infinite) is taken as CLAMP_RIGID, and
    stays rigid at m = 1 (the nominal structure, as every other factor leaves it at 1)."""
    if m == 1.0:
        return p
    k_c = p.clamp_rotational_stiffness if math.isfinite(p.clamp_rotational_stiffness) else CLAMP_RIGID
    return p.replace(clamp_rotational_stiffness=k_c / m)


# N m/rad: the rotational stiffness of a rigid clamp (structure.clamp_rotational_stiffness_nm_per_rad null) when its
# compliance is updated: about 1e6 x the beam's EI / L (146 N m), the first three natural frequencies within 3e-6 of
# the rigid clamp's. A clamp of 2e5 N m/rad (m = 500) lowers them by 0.14 %, one of 2e4 by 1.4 %, and it shows most in
# the residues of the sensor nearest the clamp
CLAMP_RIGID = 1.0e8

FACTORS = {
    f.name: f
    for f in (
        StructuralFactor(
            "stiffness_scale",
            "Young's modulus E (the beam's bending and axial stiffness)",
            0.05,
            lambda p, m: p.replace(youngs_modulus=m * p.youngs_modulus),
        ),
        StructuralFactor("mass_scale", "the beam's density", 0.03, lambda p, m: p.replace(density=m * p.density)),
        StructuralFactor(
            "transducer_mass_scale", "every transducer mass (accelerometers and force transducer)", 0.5, _scale_masses
        ),
        # the force transducer against the accelerometers: transducer_mass_scale moves them together, this one the force
        # transducer's alone (at the drive point; the residues tell it from the accelerometers' to about half its prior)
        StructuralFactor(
            "force_transducer_mass_scale",
            "the force transducer's mass, beyond transducer_mass_scale (the accelerometers' and its own)",
            0.5,
            lambda p, m: p.replace(force_transducer_mass=m * p.force_transducer_mass),
        ),
        StructuralFactor(
            "tangential_lever_arm_scale",
            "the tangential lever arm (height of the contact line)",
            0.1,
            lambda p, m: p.replace(tangential_lever_arm=m * p.tangential_lever_arm),
        ),
        # a log-normal prior about the nominal clamp (rigid: CLAMP_RIGID) with a spread of e^5 (x 150 at one sd):
        # clamps from rigid to about 1e4 N m/rad; the second start, 1e5 N m/rad from a rigid one, gives the fit a
        # gradient where the rigid clamp has none
        StructuralFactor(
            "clamp_compliance_scale",
            "the clamp's rotational compliance 1 / k_c (a rigid clamp taken as 1e8 N m/rad)",
            5.0,
            _scale_clamp_compliance,
            starts=(1.0e3,),
            max_prior_sd=10.0,
            needs_starts=lambda p: not math.isfinite(p.clamp_rotational_stiffness),
        ),
    )
}
DEFAULT_FACTORS = tuple(FACTORS)
# factors whose profile is also taken together (``identifiability[f]["group_profile_chi2_increase"]``): each of the two
# transducer-mass factors alone is partly taken up by the other (the masses +40 % held at nominal: 1.8 where the
# five factors without the force transducer's gave more than 4)
PROFILE_GROUPS = {"transducer_masses": ("transducer_mass_scale", "force_transducer_mass_scale")}


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


def apply_factors(params: StructureParameters, factors: dict) -> StructureParameters:
    """The structure with each named factor (multiplier of its nominal value) applied."""
    for name, value in factors.items():
        params = FACTORS[name].apply(params, float(value))
    return params


def modal_predictions(params: StructureParameters, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies (Hz) of the first ``n_modes`` structural modes and the residue magnitudes
    |phi_i(x_s) phi_i(x_d)| / (2 omega_i) (sensor, mode) of the driving-point force's accelerance."""
    model = assemble(params)
    modes = structural_modes(model, n_modes)
    phi_s = model.sensor_vectors @ modes.shapes
    phi_d = model.force_vector @ modes.shapes
    w = 2 * np.pi * modes.frequencies_hz
    return modes.frequencies_hz, np.abs(phi_s * phi_d[None, :]) / (2 * w[None, :])


def _prior_sds(names: list, contact_prior_sd: float, prior_sd) -> np.ndarray:
    """Prior sd of (ln k_t, ln k_n, ln factor for each of ``names``): ``contact_prior_sd`` for the contact, FACTORS'
    spreads for the factors unless ``prior_sd`` ({factor: sd}) replaces them; an unknown factor is refused."""
    for f in names:
        if f not in FACTORS:
            raise ValueError(f"gap.model_updating.parameters: unknown {f!r}; choose from {', '.join(FACTORS)}")
    priors = {f: FACTORS[f].prior_sd for f in names} | {k: float(v) for k, v in dict(prior_sd or {}).items()}
    return np.array([contact_prior_sd, contact_prior_sd] + [priors[f] for f in names])


def gain_basis(j: int) -> np.ndarray:
    """(j, j - 1) orthonormal basis of the plane where j channels' log gains sum to zero: the channels relative to one
    another. A gain common to every channel scales all residues as the transducer masses nearly do (exact modal data
    of masses 30 % heavy: free common gains took the update's drop below significance), so it is left out."""
    return np.linalg.qr(np.vstack([np.ones(j), np.eye(j)[: j - 1]]).T)[0][:, 1:]


class _UpdatingProblem:
    """The misfit of the structure x = (ln k_t, ln k_n, ln factors, ln channel gains) to the modal data: frequencies
    (Hz) over their standard errors and, unless ``R_id`` is None, residues over ``residue_accuracy`` of their value;
    ``sd`` the prior sds of x. ``n_gains`` (0, or the sensors' number less one): the accelerometer channels' sensitivity
    factors on their residues relative to one another (the measurement chain's, not the structure's), as coordinates
    of their logs in the plane where those sum to zero (``gain_basis``)."""

    def __init__(self, params, names, f_id, f_sd, R_id, residue_accuracy, sd, n_gains: int = 0):
        self.params, self.names, self.sd = params, names, sd
        self.f_id, self.f_sd, self.R_id, self.residue_accuracy = f_id, f_sd, R_id, residue_accuracy
        self.n = f_id.size
        self.n_gains = int(n_gains)

    def structure(self, x) -> StructureParameters:
        """The structure at x."""
        return apply_factors(
            self.params.with_contact(float(np.exp(x[0])), float(np.exp(x[1]))),
            {f: float(np.exp(v)) for f, v in zip(self.names, x[2:])},
        )

    def data_residuals(self, x) -> np.ndarray:
        """Scaled residuals of the frequencies, then of the residues (sensor by sensor); 1e3 each where the
        structure has no modes to compare."""
        n, R_id = self.n, self.R_id
        try:
            f, R = modal_predictions(self.structure(x), n)
        except ValueError:
            return np.full(n + (0 if R_id is None else R_id.size), 1e3)
        r = [(f - self.f_id) / self.f_sd]
        if R_id is not None:
            if self.n_gains:
                R = R * np.exp(gain_basis(R.shape[0]) @ np.asarray(x[-self.n_gains :], float))[:, None]
            r.append(((R - R_id) / (self.residue_accuracy * R_id)).ravel())
        return np.concatenate(r)

    def fit(self, x_centre, free, start=None):
        """(x, least-squares result) of the maximum a posteriori fit of the ``free`` entries of x, the others held at
        ``x_centre``, which is the centre of the prior and the start (or ``start``'s free entries)."""
        sd = self.sd

        def res(z):
            x = x_centre.copy()
            x[free] = z
            return np.concatenate([self.data_residuals(x), ((x - x_centre) / sd)[free]])

        z0 = (x_centre if start is None else np.asarray(start, float))[free]
        # central differences with absolute steps of 1e-5 of the logs: the default forward steps (1.5e-8) resolve the
        # flat directions (the lever arm against k_t, a stiff k_n) no better than the eigensolver's rounding, so the
        # fit stopped wherever the noisy Jacobian sent it, a posterior misfit several times the optimum's, and a
        # change of 1e-8 in the frequencies moved the factors by per cents. scipy's diff_step is relative to x,
        # a step of 1e-5 |ln factor|, 1e-11 at a factor of 1.000001: the posterior sd of a lever arm the data do not
        # bind came out 0.0002-0.1 (docs/measurements.md, "The updating's Jacobian")
        from scipy.optimize import least_squares  # here: the contact-force jobs import this module for its results

        sol = least_squares(
            res,
            z0,
            jac=central_difference_jacobian(res, DIFF_STEP),
            x_scale=sd[free] * 0.1,
            xtol=1e-10,
            ftol=1e-12,
            max_nfev=400,
        )
        x = x_centre.copy()
        x[free] = sol.x
        return x, sol


def null_drop_weights(data_jacobian, sd, n_contact: int = 2, n_nuisance: int = 0) -> np.ndarray:
    """The weights lambda_i of the update's chi^2 drop under the nominal structure: drop ~ sum_i lambda_i chi^2_1.

    data_jacobian: (n_data, p) Jacobian of the scaled data residuals (unit variance) in x = (ln k_t, ln k_n, ln
    factors); sd: (p,) prior sds of x; the first ``n_contact`` entries, and the last ``n_nuisance`` (the channel gains),
    are fitted in the nominal fit too. Linearised,
    a fit with the Gaussian prior P = diag(1 / sd^2) leaves the residual (I - H) e with the hat matrix
    H = J (J^T J + P)^-1 J^T, so the drop from the nominal fit (H0, the contact columns) to the update (H1) is
    e^T [(I - H0)^2 - (I - H1)^2] e, whose null distribution is sum_i lambda_i chi^2_1 over that matrix's eigenvalues.
    A factor the data bind adds a weight near 1 (k bound factors: chi^2_k), one the data leave at its prior a
    weight near 0 (posterior sd / prior sd r: 1 - r^4 for a factor uncorrelated with the others)."""
    J = np.asarray(data_jacobian, float)
    P = np.diag(1.0 / np.asarray(sd, float) ** 2)
    eye = np.eye(J.shape[0])

    def rest(cols):  # I - H over the columns cols
        Jc = J[:, cols]
        return eye - Jc @ np.linalg.solve(Jc.T @ Jc + P[np.ix_(cols, cols)], Jc.T)

    p = J.shape[1]
    R0, R1 = rest(list(range(n_contact)) + list(range(p - n_nuisance, p))), rest(list(range(p)))
    A = R0 @ R0 - R1 @ R1
    return np.clip(np.linalg.eigvalsh(0.5 * (A + A.T)), 0.0, None)


def chi2_drop_threshold(weights, confidence: float) -> float:
    """The drop of chi^2 that sum_i w_i chi^2_1 (``null_drop_weights``) exceeds with probability 1 - confidence, by
    Satterthwaite's match of mean and variance, c chi^2_nu with c = sum w^2 / sum w, nu = (sum w)^2 / sum w^2 (exact
    where every weight is 0 or 1: k weights of 1 give chi^2_k(confidence)); inf where no weight is left (the data
    bind no factor, and no drop is significant)."""
    from scipy.stats import chi2  # here: scipy.stats takes 0.3 s to import

    w = np.asarray(weights, float)
    s1, s2 = float(w.sum()), float((w**2).sum())
    if s1 <= 1e-9:
        return math.inf
    return float(s2 / s1 * chi2.ppf(confidence, s1 * s1 / s2))


def _posterior_identifiability(jacobian, sd, labels: list) -> tuple[np.ndarray, dict]:
    """(covariance of x from the Jacobian of the residuals (data + prior) at the optimum, the linearised posterior;
    {label: posterior sd, prior sd, their ratio, whether the data bound it (ratio < IDENTIFIED), the parameter it
    correlates with most and the correlation})."""
    J = jacobian
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(J.T @ J)
    post_sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    corr = cov / np.outer(post_sd, post_sd)
    ident = {}
    for i, name in enumerate(labels):
        others = [j for j in range(len(labels)) if j != i]
        j = max(others, key=lambda j: abs(corr[i, j])) if others else None
        ratio = float(post_sd[i] / sd[i])
        ident[name] = {
            "posterior_sd": float(post_sd[i]),
            "prior_sd": float(sd[i]),
            "posterior_over_prior": ratio,
            "bound_by_data": bool(ratio < IDENTIFIED),
            "most_correlated_with": labels[j] if j is not None else None,
            "correlation": float(corr[i, j]) if j is not None else None,
        }
    return cov, ident


class ChannelGainTest(NamedTuple):
    """``channel_gains_significant``'s answer, with the two nominal fits (x of k_t, k_n, the factors at nominal and,
    in ``x_with``, the gains) that ``update_structure`` starts from."""

    significant: bool
    gains: tuple
    sd: tuple
    x_with: np.ndarray
    x_without: np.ndarray


def channel_gains_significant(
    params, names, f_id, f_sd, R_id, residue_accuracy, sd, gain_sd, confidence
) -> ChannelGainTest:
    """The channels' gains relative to one another (``gain_basis``, prior sd ``gain_sd`` of their logs) fitted with k_t
    and k_n on the nominal structure, the posterior sd of each one's log, and whether they lower its chi^2 by more
    than chi^2_(j-1)(confidence): the residues call the channels miscalibrated. Where they
    do not, the update is made without them: fitted always, they took part of a structure's own misfit at the sensors
    (the compound benchmark's update of compound-14-s1 went from 16.2 % to 13.6 % instead of 15.0 %, and its normal
    dashpot was no longer named)."""
    from scipy.stats import chi2  # here: scipy.stats takes 0.3 s to import

    j = R_id.shape[0]
    x = np.array([np.log(params.k_t), np.log(params.k_n)] + [0.0] * (len(names) + j - 1))
    sd_g = np.concatenate([sd, np.full(j - 1, float(gain_sd))])
    with_gains = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd_g, j - 1)
    without = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd, 0)
    free = np.array([True, True] + [False] * len(names) + [True] * (j - 1))
    x_g, sol = with_gains.fit(x, free)
    x_0, _ = without.fit(x[: 2 + len(names)], free[: 2 + len(names)])
    drop = float(np.sum(without.data_residuals(x_0) ** 2) - np.sum(with_gains.data_residuals(x_g) ** 2))
    B = gain_basis(j)
    J = sol.jac  # of (data, prior) residuals in the free entries: k_t, k_n, the gains
    try:
        cov = np.linalg.inv(J.T @ J)[2:, 2:]
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(J.T @ J)[2:, 2:]
    gains = tuple(float(v) for v in np.exp(B @ x_g[len(x_g) - (j - 1) :]))
    gain_sd_post = tuple(float(v) for v in np.sqrt(np.diag(B @ cov @ B.T)))
    return ChannelGainTest(drop > float(chi2.ppf(confidence, j - 1)), gains, gain_sd_post, x_g, x_0)


def update_structure(
    params: StructureParameters,
    f_id_hz,
    f_sigma_hz,
    residues,
    residue_accuracy: float = 0.01,
    factors=DEFAULT_FACTORS,
    contact_prior_sd: float = 3.0,
    confidence: float = 0.95,
    prior_sd=None,
    gain_sd: float = 0.0,
) -> UpdatingResult:
    """Update the structure ``params`` (with its k_t, k_n as the start) to the random test's modal data.

    f_id_hz, f_sigma_hz: (n,) identified natural frequencies and their standard errors (Hz); residues:
    (n_sensors, n) |R_si| of the modal fit (or None: frequencies alone); residue_accuracy: relative standard
    error of a residue; factors: names of FACTORS to update; contact_prior_sd: prior sd of ln k_t and
    ln k_n (wide); confidence: the update is accepted when chi^2 drops by more than ``chi2_drop_threshold``
    (chi^2_k(confidence) for k factors the data bind); prior_sd: {factor: sd of its ln} replacing FACTORS' prior
    spreads (a lever arm measured to 1 %: 0.01); gain_sd: prior sd of the ln of the accelerometer channels' sensitivity
    factors relative to one another (their logs summing to zero, ``gain_basis``) on the residues (0: none); where they
    lower the nominal fit's chi^2 significantly (``channel_gains_significant``) they are fitted with k_t and k_n in the
    nominal fit and in the update alike
    (the measurement chain's, not counted among the factors the update adds; ``UpdatingResult.channel_gains``): a
    channel 2 % off otherwise made the random test's residues call for a clamp compliance 900 times the nominal's.
    See the module's docstring."""
    f_id = np.asarray(f_id_hz, float)
    f_sd = np.asarray(f_sigma_hz, float)
    n = f_id.size
    R_id = None if residues is None else np.asarray(residues, float)
    names = [str(f) for f in factors]
    sd = _prior_sds(names, contact_prior_sd, prior_sd)
    n_gains = R_id.shape[0] - 1 if R_id is not None and gain_sd > 0 and R_id.shape[0] > 1 else 0
    gain_test = None
    if n_gains:
        gain_test = channel_gains_significant(
            params, names, f_id, f_sd, R_id, residue_accuracy, sd, gain_sd, confidence
        )
        if not gain_test.significant:
            n_gains = 0  # channels the residues do not call miscalibrated: the update as without the gains
    sd = np.concatenate([sd, np.full(n_gains, float(gain_sd))])
    x_nom = np.array([np.log(params.k_t), np.log(params.k_n)] + [0.0] * (len(names) + n_gains))
    problem = _UpdatingProblem(params, names, f_id, f_sd, R_id, residue_accuracy, sd, n_gains)
    contact_only = np.array([True, True] + [False] * len(names) + [True] * n_gains)
    if gain_test is None:
        x0, _ = problem.fit(x_nom, contact_only)  # the nominal structure with k_t, k_n refitted to the same data
    else:  # the same fit, made by the gains' test
        x0 = gain_test.x_with if gain_test.significant else gain_test.x_without
    chi2_nominal = float(np.sum(problem.data_residuals(x0) ** 2))
    free = np.ones(x_nom.size, bool)
    x_start = x_nom.copy()
    x_start[:2] = x0[:2]  # the contact parameters start (and their wide prior is centred) at the refitted k_t, k_n
    x1, sol = problem.fit(x_start, free)
    for i, name in enumerate(names):  # the further starts of factors with no gradient at their nominal value
        factor = FACTORS[name]
        for start in factor.starts if factor.needs_starts is None or factor.needs_starts(params) else ():
            x_alt = x1.copy()
            x_alt[2 + i] = np.log(start)
            x2, sol2 = problem.fit(x_start, free, start=x_alt)
            if sol2.cost < sol.cost:
                x1, sol = x2, sol2
    data_residuals = problem.data_residuals(x1)
    chi2_updated = float(np.sum(data_residuals**2))
    weights = null_drop_weights(sol.jac[: data_residuals.size], sd, n_nuisance=n_gains)
    threshold = chi2_drop_threshold(weights, confidence)
    accepted = bool(names) and bool(chi2_nominal - chi2_updated > threshold)
    cov, ident = _posterior_identifiability(sol.jac, sd, ["k_t", "k_n"] + names + [f"gain_{k}" for k in range(n_gains)])
    # the channel gains' posterior (marginalised out of the structure's: its covariance is the block without them)
    for k in range(n_gains):
        ident.pop(f"gain_{k}")
    gain_cov = cov[2 + len(names) :, 2 + len(names) :]
    cov = cov[: 2 + len(names), : 2 + len(names)]

    # each factor's profile: the posterior misfit's rise when it is held at its nominal value (also for an update
    # not accepted here: the records may accept it, and the verdict reads the profiles)
    def profile(idx) -> float:  # the posterior misfit's rise with the factors idx held at nominal
        hold = free.copy()
        hold[[2 + i for i in idx]] = False
        _, sol_h = problem.fit(x_start, hold, start=x1)  # from the update: the others are near their optimum
        return float(max(2.0 * (sol_h.cost - sol.cost), 0.0))

    for i, name in enumerate(names):
        ident[name]["profile_chi2_increase"] = profile([i])
    # factors that together make one quantity (the transducer masses: all of them, and the force transducer's
    # beyond): held at nominal together, as each alone is partly taken up by the other
    for group, members in PROFILE_GROUPS.items():
        idx = [i for i, name in enumerate(names) if name in members]
        if len(idx) > 1:
            rise = profile(idx)
            for i in idx:
                ident[names[i]].update(group=group, group_profile_chi2_increase=rise)
    x = x1 if accepted else x0
    f_best, _ = modal_predictions(problem.structure(x), n)
    structure_alone = None
    if n_gains:
        # the same update without the gains: a clamp that gives, say, shapes the residues at the sensors as channel
        # gains nearly do, and the gains' prior is the cheaper (a rig with a 2e5 N m/rad clamp, E -3 %, transducers
        # +40 %: gains of 0.6-0.9 % took the clamp's place, chi^2 1.08 against 1.14 without them, and its dashpot
        # was refitted at 673 s/m for 300). Where the drop the gains add is not significant, the records decide
        from scipy.stats import chi2 as _chi2

        alone = update_structure(
            params, f_id_hz, f_sigma_hz, residues, residue_accuracy, factors, contact_prior_sd, confidence, prior_sd
        )
        drop = float(alone.chi2_updated - chi2_updated)
        bar = float(_chi2.ppf(confidence, n_gains))
        structure_alone = {
            **alone.summary(),
            "gains_drop": drop,
            "gains_threshold": bar,
            "gains_needed": bool(drop > bar),
            "nominal_channel_gains": list(gain_test.gains),
            "nominal_channel_gain_sd": list(gain_test.sd),
        }
    return UpdatingResult(
        {f: float(np.exp(v)) for f, v in zip(names, x[2:])},
        float(np.exp(x[0])),
        float(np.exp(x[1])),
        problem.structure(x),
        chi2_nominal,
        chi2_updated,
        accepted,
        ident,
        f_best,
        int(n + (0 if R_id is None else R_id.size)),
        cov.tolist(),
        params,
        None
        if accepted or not names
        else {
            "factors": {f: float(np.exp(v)) for f, v in zip(names, x1[2:])},
            "k_t": float(np.exp(x1[0])),
            "k_n": float(np.exp(x1[1])),
        },
        "random_test" if accepted else "",
        chi2_threshold=threshold,
        effective_factors=float(np.sum(weights)),
        channel_gains=tuple(float(v) for v in np.exp(gain_basis(n_gains + 1) @ x[len(x) - n_gains :]))
        if n_gains
        else (gain_test.gains if gain_test is not None else ()),
        channel_gain_sd=tuple(
            float(v) for v in np.sqrt(np.diag(gain_basis(n_gains + 1) @ gain_cov @ gain_basis(n_gains + 1).T))
        )
        if n_gains
        else (gain_test.sd if gain_test is not None else ()),
        channel_gains_significant=gain_test is not None and gain_test.significant,
        structure_alone=structure_alone,
    )
